#!/usr/bin/env python3
"""Two-file import cycles among a crate's modules (issue 42's check).

    scripts/module-cycles.py CRATE_SRC_DIR... [--reexports] [-v]

A module is a file (`a.rs` or `a/mod.rs`: module `a`). Its dependencies are
the `crate::…`, `super::…` and `self::…` paths it names outside comments
(test modules in the file included), each mapped to the longest module
prefix; `crate::{a, b}` and `super::{a, b}` groups are split. A module's
edges to its own ancestors are left out: a child naming its parent
(`use super::*` in a test file, or an item of the parent) is how Rust
nests modules, not a cycle between two concerns. Prints each pair of
modules that name each other; exit status 1 when there is one.

--reexports also follows the crate root's `pub use a::{X, …}`, so that
`crate::X` counts as naming module `a` (stricter: a cycle through the
root's re-exports is a cycle too). -v prints every module's edges.
"""
import os
import re
import sys

args = [a for a in sys.argv[1:] if not a.startswith('-')]
reexports = '--reexports' in sys.argv
verbose = '-v' in sys.argv
if not args:
    sys.exit(__doc__)
status = 0
for root in args:
    mods = {}
    for dp, _, fn in os.walk(root):
        for f in fn:
            if not f.endswith('.rs'):
                continue
            p = os.path.relpath(os.path.join(dp, f), root)[:-3].split(os.sep)
            if p[-1] in ('mod', 'lib', 'main'):
                p = p[:-1]
            mods[tuple(p)] = os.path.join(dp, f)
    names = {}
    if reexports and () in mods:
        lib = open(mods[()]).read()
        for m in re.finditer(r'pub(?:\(crate\))? use ([\w:]+)::\{([^}]*)\}', lib):
            for item in m.group(2).split(','):
                item = item.strip().split(' as ')[-1].strip()
                if item:
                    names[item] = m.group(1).split('::')
        for m in re.finditer(r'pub(?:\(crate\))? use ([\w:]+)::(\w+);', lib):
            names[m.group(2)] = m.group(1).split('::')

    def resolve(path):
        if path and path[0] in names and (path[0],) not in mods:
            path = names[path[0]] + path[1:]
        for n in range(len(path), 0, -1):
            if tuple(path[:n]) in mods:
                return tuple(path[:n])
        return None

    deps = {m: set() for m in mods}
    for m, f in mods.items():
        src = re.sub(r'//[^\n]*', '', open(f).read())
        found = []
        for g in re.finditer(r'\b(crate|super|self)((?:::\w+)+)', src):
            found.append((g.group(1), g.group(2).split('::')[1:]))
        for g in re.finditer(r'\b(crate|super|self)::\{([^}]*)\}', src):
            for item in g.group(2).split(','):
                item = item.strip().split('::')
                if item and item[0]:
                    found.append((g.group(1), item))
        for kind, rest in found:
            base = [] if kind == 'crate' else list(m) if kind == 'self' else list(m[:-1])
            while rest and rest[0] == 'super':
                base, rest = base[:-1], rest[1:]
            t = resolve(base + rest)
            if t is not None and t != m and m[:len(t)] != t:
                deps[m].add(t)
    name = lambda t: '::'.join(t) or 'lib'
    for a in sorted(deps):
        for b in sorted(deps[a]):
            if a < b and a in deps.get(b, ()):
                print(f'{root}: cycle: {name(a)} <-> {name(b)}')
                status = 1
    if verbose:
        for a in sorted(deps):
            print(f'{root}: {name(a)} -> {", ".join(sorted(map(name, deps[a])))}')
sys.exit(status)
