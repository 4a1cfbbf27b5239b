#!/usr/bin/env python3
"""The engine's modules form a tree, not a circle (docs/architecture.md).

A module is a file name without its extension: contact.c and contact.h are
the module `contact`.  Module A depends on module B when A's source or
header includes B's header, or when A's object calls (or reads) a symbol
B's object defines.  The check fails, naming the loop and each edge's
reason, when some modules depend on each other in a loop.

    engine_tree.py --src src/engine [--objects 'a.o;b.o;...']
    engine_tree.py --self-test CC

--objects takes the engine's object files (CMake's $<TARGET_OBJECTS:...>,
separated by ';'); without it only the includes are checked.  --self-test
plants a loop of includes and a loop of calls and fails unless both are
caught.  Exit 0: a tree; 1: a loop (listed on stderr); 2: bad usage.
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s*"([^"]+)"', re.M)


def module_of(path):
    return os.path.splitext(os.path.basename(path))[0]


def include_edges(src):
    """{(a, b): reason} for each engine header b that a file of a includes."""
    files = [f for f in sorted(os.listdir(src)) if f.endswith(('.c', '.h'))]
    edges = {}
    for f in files:
        with open(os.path.join(src, f), encoding='utf-8') as fh:
            text = fh.read()
        a = module_of(f)
        for inc in INCLUDE.findall(text):
            b = module_of(inc)  # an engine header, not a public one (cohfrac/world.h)
            if b != a and inc in files and inc.endswith('.h'):
                edges.setdefault((a, b), f'{f} includes "{inc}"')
    return edges


def call_edges(objects):
    """{(a, b): reason} for each symbol a's object uses and b's defines."""
    defined, used = {}, {}
    for o in objects:
        out = subprocess.run(['nm', '--defined-only', '-g', o], capture_output=True, text=True,
                             check=True).stdout
        mod = module_of(module_of(o))  # contact.c.o -> contact
        for line in out.splitlines():
            parts = line.split()
            if len(parts) == 3:
                defined[parts[2]] = mod
        out = subprocess.run(['nm', '-u', o], capture_output=True, text=True, check=True).stdout
        used[mod] = {line.split()[-1] for line in out.splitlines() if line.strip()}
    edges = {}
    for a, symbols in used.items():
        for sym in sorted(symbols):
            b = defined.get(sym)
            if b and b != a:
                edges.setdefault((a, b), f'{a} uses {sym}')
    return edges


def loops(edges):
    """The strongly connected components of more than one module (Tarjan)."""
    graph = {}
    for a, b in edges:
        graph.setdefault(a, []).append(b)
        graph.setdefault(b, [])
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def check(src, objects):
    edges = include_edges(src)
    for e, why in call_edges(objects).items():
        edges.setdefault(e, why)
    bad = loops(edges)
    for comp in bad:
        print('engine_tree: these engine modules depend on each other in a loop: ' +
              ', '.join(comp), file=sys.stderr)
        for (a, b), why in sorted(edges.items()):
            if a in comp and b in comp:
                print(f'  {a} -> {b}: {why}', file=sys.stderr)
    if bad:
        print('engine_tree: move what both need below both, or pass it down as an argument '
              '(docs/architecture.md, "The engine\'s modules")', file=sys.stderr)
    return 1 if bad else 0


def self_test(cc):
    fails = 0
    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, 'engine')
        os.mkdir(src)
        files = {'low.h': 'int low(void);\n', 'low.c': '#include "low.h"\nint low(void) { return 1; }\n',
                 'a.h': 'int a(void);\n', 'b.h': 'int b(void);\n',
                 'a.c': '#include "a.h"\n#include "low.h"\nint a(void) { return low(); }\n',
                 'b.c': '#include "b.h"\n#include "a.h"\nint b(void) { return a(); }\n'}
        for name, text in files.items():
            with open(os.path.join(src, name), 'w', encoding='utf-8') as fh:
                fh.write(text)

        def objects():
            out = []
            for c in ('low.c', 'a.c', 'b.c'):
                o = os.path.join(tmp, c + '.o')
                subprocess.run([cc, '-c', '-I', src, os.path.join(src, c), '-o', o], check=True)
                out.append(o)
            return out

        if check(src, objects()) != 0:
            print('FAIL: a tree was taken for a loop')
            fails += 1
        else:
            print('ok: a tree passes')
        with open(os.path.join(src, 'a.h'), 'a', encoding='utf-8') as fh:
            fh.write('#include "b.h"\n')  # a -> b by include, b -> a by call and include
        if check(src, []) == 0:
            print('FAIL: a loop of includes was not caught')
            fails += 1
        else:
            print('ok: a loop of includes is caught')
        with open(os.path.join(src, 'a.h'), 'w', encoding='utf-8') as fh:
            fh.write('int a(void);\n')
        with open(os.path.join(src, 'a.c'), 'w', encoding='utf-8') as fh:
            fh.write('int b(void);\nint a(void) { return b() - 1; }\n')  # a calls b: no include
        if check(src, objects()) == 0:
            print('FAIL: a loop of calls was not caught')
            fails += 1
        else:
            print('ok: a loop of calls is caught')
    return 1 if fails else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--src', help='the engine source folder')
    ap.add_argument('--objects', default='', help="the engine's object files, ';'-separated")
    ap.add_argument('--self-test', metavar='CC', help='plant loops and check they are caught')
    args = ap.parse_args()
    if args.self_test:
        return self_test(args.self_test)
    if not args.src:
        ap.print_usage(sys.stderr)
        return 2
    objects = [o for o in args.objects.split(';') if o]
    rc = check(args.src, objects)
    if rc == 0:
        print(f'engine_tree: {len(include_edges(args.src))} include and '
              f'{len(call_edges(objects))} call dependencies, no loop')
    return rc


if __name__ == '__main__':
    sys.exit(main())
