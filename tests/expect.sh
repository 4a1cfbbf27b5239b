# Sourced by the shell tests of the command line: a scratch directory
# $tmp (removed at exit), a failure count $fails, and
#   expect CODE WHAT CMD...
# which runs CMD, checks its exit status, and prints "ok" with the first
# line it printed that names cohfrac, or "FAIL" with the last lines of its
# output.
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
expect() {
    code=$1; what=$2; shift 2
    "$@" >"$tmp/log" 2>&1
    rc=$?
    if [ "$rc" -eq "$code" ]; then echo "ok    exit $rc: $what: $(grep -m1 'cohfrac' "$tmp/log" | cut -c1-150)"
    else echo "FAIL  exit $rc (want $code): $what"; sed 's/^/      /' "$tmp/log" | tail -20; fails=$((fails + 1)); fi
}
