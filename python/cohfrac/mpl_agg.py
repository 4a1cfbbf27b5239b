"""matplotlib for the plot scripts of tools/: the Agg backend (no display),
or exit status 3 with a hint when Debian's python3-matplotlib is missing;
saving a figure whole or not at all."""
import os
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


def save_png(fig, path):
    """Lay the figure out and write it to PATH.tmp, then rename it to PATH."""
    fig.tight_layout()
    tmp = path + ".tmp"
    fig.savefig(tmp, dpi=110, format="png")
    os.replace(tmp, path)
