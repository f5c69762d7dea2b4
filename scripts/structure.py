#!/usr/bin/env python3
"""The source tree's shape, checked: import circles between the files of each crate, files
over 600 lines and functions over 100 lines.

A file imports another when it names an item defined there: in a `use` tree or a path
written in the code (`crate::`, `super::`, `self::` or a child module's name), followed
through `pub use` re-exports to the file that defines the item. A module's own `pub use`
of an item is its table of contents, not an import (a parent listing what its children
define is not a dependency on them), and neither is declaring a child (`mod x;`);
`#[cfg(test)]` modules are left out, as are other crates.

Usage: python3 scripts/structure.py [--check]. With --check the exit status is 1 when a
circle, a long file or a long function is found that is not listed below with its reason.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CRATES = ["core", "ffi", "py", "sim", "nostd-check"]
MAX_FILE_LINES = 600
MAX_FN_LINES = 100
# Crates whose functions are held to MAX_FN_LINES (the C API's entry points are thin).
FN_CRATES = ["core", "sim", "py"]

# Known exceptions, each with its reason: "path" or "path:function".
EXCEPTIONS: dict[str, str] = {
    "crates/core/src/error/build.rs:fmt": "Display of BuildError: one match arm per variant, "
    "each a message; splitting it would scatter the messages of one type",
    "crates/core/src/error/load.rs:fmt": "Display of LoadError: one match arm per variant, "
    "each a message; splitting it would scatter the messages of one type",
}

ITEM = re.compile(
    r"^\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\s*\([^)]*\))?\s+)?(?:unsafe\s+|const\s+|async\s+|extern\s+\"C\"\s+)*"
    r"(fn|struct|enum|const|static|type|trait|union|macro_rules!)\s*(\w+)",
    re.M,
)
TOKEN = re.compile(
    r"//[^\n]*|/\*.*?\*/|b?r(#*)\".*?\"\1|b?\"(?:\\.|[^\"\\])*\"|b?'(?:\\.|[^'\\\n])'",
    re.S,
)


def blank(text: str) -> str:
    """The source with comments, strings and char literals blanked (newlines kept), so
    braces and paths are read from code alone."""

    def keep_lines(m: re.Match[str]) -> str:
        s = m.group(0)
        return "".join(c if c == "\n" else " " for c in s)

    return TOKEN.sub(keep_lines, text)


def module_of(src: Path, file: Path) -> tuple[str, ...]:
    rel = file.relative_to(src).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts.pop()
    return tuple(parts)


def strip_tests(code: str) -> str:
    """The code without `#[cfg(test)]` items (blanked, lines kept)."""
    out = list(code)
    for m in re.finditer(r"#\[cfg\(test\)\]", code):
        i = m.end()
        depth, start = 0, None
        while i < len(code):
            c = code[i]
            if c == ";" and start is None:
                break
            if c == "{":
                depth += 1
                start = start if start is not None else i
            elif c == "}":
                depth -= 1
                if depth == 0:
                    break
            i += 1
        for k in range(m.start(), min(i + 1, len(code))):
            if out[k] != "\n":
                out[k] = " "
    return "".join(out)


def expand_use(tree: str, prefix: list[str]) -> list[list[str]]:
    """The paths of one `use` tree (`a::{b, c::{d as e}, self}`), `as` names dropped."""
    tree = tree.strip()
    if not tree:
        return []
    depth, brace = 0, None
    for i, c in enumerate(tree):
        if c == "{":
            if depth == 0:
                brace = i
            depth += 1
        elif c == "}":
            depth -= 1
    if brace is None:
        head = re.sub(r"\s+as\s+\w+$", "", tree)
        segs = [s for s in head.split("::") if s]
        if segs == ["self"]:
            return [prefix]
        return [prefix + segs]
    head = [s for s in tree[:brace].split("::") if s]
    inner = tree[brace + 1 : tree.rindex("}")]
    parts, depth, cur = [], 0, ""
    for c in inner:
        if c == "," and depth == 0:
            parts.append(cur)
            cur = ""
            continue
        depth += c == "{"
        depth -= c == "}"
        cur += c
    parts.append(cur)
    out: list[list[str]] = []
    for p in parts:
        out += expand_use(p, prefix + head)
    return out


class Crate:
    def __init__(self, name: str):
        self.name = name
        self.src = ROOT / "crates" / name / "src"
        self.files = sorted(self.src.rglob("*.rs"))
        self.mods = {module_of(self.src, f): f for f in self.files}
        self.code = {f: strip_tests(blank(f.read_text())) for f in self.files}
        self.defs: dict[Path, set[str]] = {}
        self.reexports: dict[Path, dict[str, list[str]]] = {}
        self.globs: dict[Path, list[list[str]]] = {}
        for f in self.files:
            self.defs[f] = {m.group(2) for m in ITEM.finditer(self.code[f])}
            self.reexports[f], self.globs[f] = {}, []
            here = module_of(self.src, f)
            for m in re.finditer(r"\bpub(?:\s*\([^)]*\))?\s+use\s+([^;]+);", self.code[f]):
                for path in expand_use(m.group(1), []):
                    absolute = self.absolute(here, path)
                    if absolute is None:
                        continue
                    if absolute[-1] == "*":
                        self.globs[f].append(absolute[:-1])
                    else:
                        alias = re.search(r"(\w+)\s*$", path[-1]).group(1)
                        self.reexports[f][alias] = absolute

    def absolute(self, here: tuple[str, ...], path: list[str]) -> list[str] | None:
        """The path from the crate root, or None for another crate's."""
        if not path:
            return None
        first = path[0]
        if first == "crate":
            return path[1:]
        if first in ("self", "super"):
            base = list(here)
            rest = list(path)
            while rest and rest[0] in ("self", "super"):
                if rest.pop(0) == "super":
                    if not base:
                        return None
                    base.pop()
            return base + rest
        if tuple(here) + (first,) in self.mods:
            return list(here) + path
        return None

    def resolve(self, path: list[str], seen: int = 0) -> Path | None:
        """The file defining the item (or module) the absolute path names."""
        for cut in range(len(path), -1, -1):
            mod = tuple(path[:cut])
            if mod in self.mods:
                break
        else:
            return None
        f = self.mods[mod]
        rest = path[cut:]
        if not rest or seen > 8:
            return f
        name = rest[0]
        if name in self.defs[f]:
            return f
        if name in self.reexports[f]:
            return self.resolve(self.reexports[f][name] + rest[1:], seen + 1)
        for g in self.globs[f]:
            target = self.resolve(g + rest, seen + 1)
            if target is not None and target != self.mods.get(tuple(g)):
                return target
        return f

    def edges(self) -> dict[Path, dict[Path, set[str]]]:
        out: dict[Path, dict[Path, set[str]]] = defaultdict(lambda: defaultdict(set))
        for f in self.files:
            here = module_of(self.src, f)
            code = self.code[f]
            paths: list[list[str]] = []
            for m in re.finditer(r"(\bpub(?:\s*\([^)]*\))?\s+)?\buse\s+([^;]+);", code):
                if m.group(1) is None:
                    paths += expand_use(m.group(2), [])
            uses = re.sub(r"\buse\s+[^;]+;", " ", code)
            for m in re.finditer(r"\b((?:crate|super|self|\w+)(?:\s*::\s*\w+)+)", uses):
                paths.append([s.strip() for s in m.group(1).split("::")])
            for path in paths:
                absolute = self.absolute(here, path)
                if absolute is None:
                    continue
                if absolute and absolute[-1] == "*":
                    absolute = absolute[:-1]
                target = self.resolve(absolute)
                if target is None or target == f:
                    continue
                # A module's own path to a child it declares, with nothing taken from it,
                # is the declaration, not an import.
                name = absolute[-1] if absolute else ""
                out[f][target].add(name)
        return out

    def circles(self) -> list[list[Path]]:
        """Strongly connected components of more than one file (Tarjan)."""
        graph = self.edges()
        index: dict[Path, int] = {}
        low: dict[Path, int] = {}
        stack: list[Path] = []
        on: set[Path] = set()
        found: list[list[Path]] = []
        counter = [0]
        sys.setrecursionlimit(10000)

        def visit(v: Path) -> None:
            index[v] = low[v] = counter[0]
            counter[0] += 1
            stack.append(v)
            on.add(v)
            for w in graph.get(v, {}):
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

        for f in self.files:
            if f not in index:
                visit(f)
        self.graph = graph
        return found

    def long_functions(self) -> list[tuple[Path, str, int, int]]:
        out = []
        for f in self.files:
            code = self.code[f]
            lines = code.split("\n")
            starts = [0]
            for line in lines:
                starts.append(starts[-1] + len(line) + 1)
            for m in re.finditer(r"\bfn\s+(\w+)", code):
                i = m.end()
                # The body's opening brace: the first `{` after the signature, before a `;`.
                depth_paren = 0
                while i < len(code):
                    c = code[i]
                    if c in "([<":
                        depth_paren += 1
                    elif c in ")]>" and code[i - 1 : i + 1] != "->":
                        depth_paren -= 1
                    elif c == ";" and depth_paren <= 0:
                        i = -1
                        break
                    elif c == "{" and depth_paren <= 0:
                        break
                    i += 1
                if i < 0 or i >= len(code):
                    continue
                depth = 0
                j = i
                while j < len(code):
                    if code[j] == "{":
                        depth += 1
                    elif code[j] == "}":
                        depth -= 1
                        if depth == 0:
                            break
                    j += 1
                first = code.count("\n", 0, m.start()) + 1
                last = code.count("\n", 0, j) + 1
                n = last - first + 1
                if n > MAX_FN_LINES:
                    out.append((f, m.group(1), first, n))
        return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="exit 1 on an unlisted finding")
    args = parser.parse_args()
    unlisted = 0

    def report(key: str, text: str) -> None:
        nonlocal unlisted
        if key in EXCEPTIONS:
            print(f"  {text} (listed: {EXCEPTIONS[key]})")
        else:
            unlisted += 1
            print(f"  {text}")

    for name in CRATES:
        crate = Crate(name)
        circles = crate.circles()
        print(f"{name}: {len(circles)} import circles")
        for comp in circles:
            rel = [str(p.relative_to(ROOT)) for p in comp]
            ties = []
            for a in comp:
                for b, names in sorted(crate.graph.get(a, {}).items()):
                    if b in comp:
                        ties.append(f"{a.name} -> {b.name}: {', '.join(sorted(names))}")
            report(" ".join(rel), " <-> ".join(rel) + " [" + "; ".join(ties) + "]")
    print(f"source files over {MAX_FILE_LINES} lines:")
    for name in CRATES:
        for f in sorted((ROOT / "crates" / name / "src").rglob("*.rs")):
            n = f.read_text().count("\n")
            if n > MAX_FILE_LINES:
                rel = str(f.relative_to(ROOT))
                report(rel, f"{rel}: {n}")
    print(f"functions over {MAX_FN_LINES} lines in {', '.join(FN_CRATES)}:")
    for name in FN_CRATES:
        for f, fn, line, n in Crate(name).long_functions():
            rel = str(f.relative_to(ROOT))
            report(f"{rel}:{fn}", f"{rel}:{line} {fn}: {n}")
    print(f"{unlisted} findings not listed as exceptions")
    return 1 if args.check and unlisted else 0


if __name__ == "__main__":
    sys.exit(main())
