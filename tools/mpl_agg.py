"""matplotlib for the plot scripts of tools/: the Agg backend (no display),
or exit status 3 with a hint when Debian's python3-matplotlib is missing."""
import sys


def pyplot(script):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        sys.stderr.write(f"{script}: matplotlib is missing "
                         "(install the Debian package python3-matplotlib)\n")
        sys.exit(3)
    return plt
