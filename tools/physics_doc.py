#!/usr/bin/python3
"""Refresh the verification table of docs/physics.md.

Usage: tools/physics_doc.py [BUILD_DIR] [DOC]
       (defaults: build and docs/physics.md of this repository)

Reads every BUILD_DIR/verification/*.json, written by the verification cases
(tests/verify_*.c, `ctest -L verification`): one JSON object per line with
the keys case, quantity, measured, reference, unit, deviation, tolerance and
pass (tolerance <= 0: the figure is reported only).  Rewrites the block
between the lines `<!-- verification:begin -->` and `<!-- verification:end -->`
of DOC with a Markdown table, grouped by case in the order of CASES (cases
not listed there follow, alphabetically), and a line giving the date of the
run (UTC, the newest json file's modification time) and the machine.

DOC is written to a temporary file beside it and renamed over it, so it is
never left half-written.  Exit status: 0 done, 2 no figures or bad input
(the message says which file and what to do).  Standard library only.
"""

import datetime
import glob
import json
import os
import subprocess
import sys
import tempfile

BEGIN = "<!-- verification:begin -->"
END = "<!-- verification:end -->"

# Order of the cases in the table (the order of docs/physics.md's list).
CASES = [
    "bounce",
    "wave_bar",
    "vibration",
    "mode_i",
    "mode_ii",
    "momentum",
    "bar_collision",
    "cfl",
    "mixed_mode_beam",
    "ledger",
]

KEYS = ("case", "quantity", "measured", "reference", "unit", "deviation", "tolerance", "pass")

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


class Failure(Exception):
    """Bad or missing input: printed, exit status 2."""


def read_figures(build_dir):
    """All figures of build_dir/verification/*.json, and the newest mtime."""
    vdir = os.path.join(build_dir, "verification")
    files = sorted(glob.glob(os.path.join(vdir, "*.json")))
    if not files:
        raise Failure(
            f"no verification results in {vdir}/*.json: run the verification cases "
            f"first (cd {build_dir} && ctest -L verification), or give the build "
            f"directory as the first argument")
    figures, newest = [], 0.0
    for path in files:
        newest = max(newest, os.path.getmtime(path))
        with open(path, encoding="utf-8") as fh:
            for lineno, line in enumerate(fh, 1):
                line = line.strip()
                if not line:
                    continue
                try:
                    fig = json.loads(line)
                except json.JSONDecodeError as e:
                    raise Failure(f"{path}:{lineno}: not a JSON object ({e.msg}): "
                                  f"re-run this case to rewrite the file") from None
                missing = [k for k in KEYS if not isinstance(fig, dict) or k not in fig]
                if missing:
                    raise Failure(f"{path}:{lineno}: missing key(s) {', '.join(missing)}: "
                                  f"re-run this case to rewrite the file")
                figures.append(fig)
    if not figures:
        raise Failure(f"the files {vdir}/*.json hold no figures: re-run "
                      f"`ctest -L verification` in {build_dir}")
    return figures, newest


def case_order(figures):
    """Case names: those of CASES first in that order, then the others sorted."""
    present = []
    for fig in figures:
        if fig["case"] not in present:
            present.append(fig["case"])
    known = [c for c in CASES if c in present]
    return known + sorted(c for c in present if c not in CASES)


def fmt(x):
    """A number in 6 significant digits (non-numbers as they are)."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return str(x)
    return f"{x:.6g}"


def cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def table(figures):
    """The Markdown table, rows grouped by case, file order within a case."""
    rows = [
        "| case | quantity | measured | reference | deviation | tolerance | result |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in case_order(figures):
        for fig in (f for f in figures if f["case"] == name):
            unit = f" {fig['unit']}" if fig["unit"] else ""
            tol = fig["tolerance"]
            reported = not isinstance(tol, (int, float)) or tol <= 0
            result = "reported" if reported else ("pass" if fig["pass"] else "**FAIL**")
            rows.append("| " + " | ".join(cell(c) for c in (
                name,
                fig["quantity"],
                fmt(fig["measured"]) + unit,
                fmt(fig["reference"]) + unit,
                f"{fig['deviation']:.3g}" if isinstance(fig["deviation"], (int, float))
                else fig["deviation"],
                "—" if reported else f"{tol:.3g}",
                result,
            )) + " |")
    return rows


def command_output(argv, fallback):
    try:
        out = subprocess.run(argv, capture_output=True, text=True, check=True).stdout.strip()
        return out or fallback
    except (OSError, subprocess.CalledProcessError):
        return fallback


def cpu_model():
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as fh:
            for line in fh:
                key, _, value = line.partition(":")
                if key.strip() in ("model name", "Model", "cpu model", "Processor"):
                    if value.strip():
                        return value.strip()
    except OSError:
        pass
    return "unknown CPU"


def machine_line(newest):
    when = datetime.datetime.fromtimestamp(newest, tz=datetime.timezone.utc)
    arch = command_output(["uname", "-m"], os.uname().machine)
    try:
        ncpu_fallback = str(len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        ncpu_fallback = str(os.cpu_count() or "?")
    ncpu = command_output(["nproc"], ncpu_fallback)
    return (f"Figures of the run of {when:%Y-%m-%d %H:%M} UTC on {arch}, "
            f"{ncpu} cores ({cpu_model()}).")


def block(figures, newest):
    n = len(figures)
    checked = [f for f in figures
               if isinstance(f["tolerance"], (int, float)) and f["tolerance"] > 0]
    passed = sum(1 for f in checked if f["pass"])
    lines = [machine_line(newest), ""]
    lines.append(f"{passed} of {len(checked)} checked figures pass; "
                 f"{n - len(checked)} reported only.")
    lines.append("")
    lines += table(figures)
    return lines


def rewrite(doc, new_block):
    try:
        with open(doc, encoding="utf-8") as fh:
            text = fh.read()
    except OSError as e:
        raise Failure(f"cannot read {doc}: {e.strerror}") from None
    lines = text.split("\n")
    starts = [i for i, l in enumerate(lines) if l.strip() == BEGIN]
    ends = [i for i, l in enumerate(lines) if l.strip() == END]
    if len(starts) != 1 or len(ends) != 1 or ends[0] < starts[0]:
        raise Failure(f"{doc}: needs exactly one line `{BEGIN}` followed by one line "
                      f"`{END}` (found {len(starts)} and {len(ends)}): restore the markers")
    out = lines[:starts[0] + 1] + [""] + new_block + [""] + lines[ends[0]:]
    directory = os.path.dirname(os.path.abspath(doc))
    fd, tmp = tempfile.mkstemp(prefix=".physics_doc.", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write("\n".join(out))
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, os.stat(doc).st_mode & 0o7777)
        os.replace(tmp, doc)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def main(argv):
    if len(argv) > 3 or any(a in ("-h", "--help") for a in argv[1:]):
        print(__doc__.strip().split("\n\n")[1], file=sys.stderr)
        return 0 if len(argv) <= 3 else 1
    build = argv[1] if len(argv) > 1 else os.path.join(REPO, "build")
    doc = argv[2] if len(argv) > 2 else os.path.join(REPO, "docs", "physics.md")
    try:
        figures, newest = read_figures(build)
        rewrite(doc, block(figures, newest))
    except Failure as e:
        print(f"physics_doc.py: {e}", file=sys.stderr)
        return 2
    print(f"physics_doc.py: {len(figures)} figures written to {doc}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
