#!/usr/bin/env python3
"""Lists import circles between the top-level modules of a crate.

    python3 .ci/import_cycles.py crates/mocap-clean/src [more src folders...]

A module is a file `src/NAME.rs` or a folder `src/NAME/` (its files are one
module). Module a uses b when its code names `crate::b` (also inside
`use crate::{b::X, ...}`) or, in `src/a.rs`, `super::b`. Unit tests
(`#[cfg(test)]` onwards) are left out: they may use anything. The crate root
(lib.rs/main.rs) is left out too: it is the front door that re-exports. Prints
each circle found and exits 1 if there is one.
"""

import re
import sys
from pathlib import Path


def strip_comments(text):
    text = re.sub(r"//[^\n]*", "", text)
    return re.sub(r"/\*.*?\*/", "", text, flags=re.S)


def without_tests(text):
    index = text.find("#[cfg(test)]")
    return text if index < 0 else text[:index]


def brace_items(text, start):
    """The top-level comma-separated items of the `{...}` opening at start."""
    depth, items, current = 0, [], ""
    for ch in text[start:]:
        if ch == "{":
            depth += 1
            if depth == 1:
                continue
        elif ch == "}":
            depth -= 1
            if depth == 0:
                items.append(current)
                return items
        if depth == 1 and ch == ",":
            items.append(current)
            current = ""
        else:
            current += ch
    return items


def used_modules(text, prefixes):
    used = set()
    for prefix in prefixes:
        for m in re.finditer(prefix + r"::(\{|\w+)", text):
            if m.group(1) == "{":
                for item in brace_items(text, m.start(1)):
                    name = re.match(r"\s*(\w+)", item)
                    if name:
                        used.add(name.group(1))
            else:
                used.add(m.group(1))
    return used


def graph(src):
    modules = {}
    for path in sorted(src.iterdir()):
        if path.is_file() and path.suffix == ".rs" and path.stem not in ("lib", "main"):
            modules[path.stem] = [path]
        elif path.is_dir():
            modules[path.name] = sorted(path.rglob("*.rs"))
    edges = {}
    for name, files in modules.items():
        uses = set()
        for f in files:
            text = without_tests(strip_comments(f.read_text()))
            prefixes = [r"\bcrate"]
            if f.parent == src:
                prefixes.append(r"\bsuper")
            uses |= used_modules(text, prefixes)
        edges[name] = sorted(u for u in uses if u in modules and u != name)
    return edges


def cycles(edges):
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    for v in edges:
        if v not in index:
            visit(v)
    return out


def main():
    found = False
    for folder in sys.argv[1:]:
        edges = graph(Path(folder))
        for component in cycles(edges):
            found = True
            links = [f"{a} -> {b}" for a in component for b in edges[a] if b in component]
            print(f"{folder}: circle among {', '.join(component)}: {'; '.join(links)}")
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
