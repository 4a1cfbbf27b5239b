#!/bin/sh
# The installed package works for a program that uses it: install the build
# into a scratch prefix, then build examples/drop.c against it both ways,
# with `pkg-config --cflags --libs cohfrac` and with find_package(cohfrac),
# and run both (they must agree on the fragments).
#   tests/install_example.sh BUILD_DIR SOURCE_DIR
set -eu
build=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
libdir=$(dirname "$(find "$prefix" -name 'libcohfrac.so' | head -1)")
export LD_LIBRARY_PATH="$libdir${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"

export PKG_CONFIG_PATH="$libdir/pkgconfig"
cc -std=c11 -Wall -Wextra -pedantic -Werror "$src/examples/drop.c" \
    $(pkg-config --cflags --libs cohfrac) -o "$tmp/drop_pkgconfig"
"$tmp/drop_pkgconfig" > "$tmp/pkgconfig.txt"
echo "pkg-config build: $(grep 'fragments at' "$tmp/pkgconfig.txt")"

cmake -S "$src/examples" -B "$tmp/examples" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$tmp/examples" >/dev/null
"$tmp/examples/drop" > "$tmp/cmake.txt"
echo "find_package build: $(grep 'fragments at' "$tmp/cmake.txt")"

grep -q 'fragments at t = 0.60 s' "$tmp/pkgconfig.txt"
cmp "$tmp/pkgconfig.txt" "$tmp/cmake.txt"
echo "both builds ran and printed the same fragments"
