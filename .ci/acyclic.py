#!/usr/bin/env python3
"""Fails if the crate's modules depend on each other in a circle.

Reads the module tree from the crate roots under src/ (lib.rs, main.rs, mps2_an386.rs): `mod x;` declarations
found as x.rs, x/mod.rs or at their `#[path]`, and inline `mod x { ... }` blocks. Every module
is one node, a parent and each of its children included (interp/mod.rs and interp/sine.rs are
two nodes). Test code is left out: items under `#[cfg(test)]`, and files named tests.rs or
test_support.rs or lying in a `tests` directory.

A module depends on the module a path in its code names: `crate::a::b::Item` names a::b, and so
does `super::Item` written in a child of a::b, or `b::Item` written in a. A path names the
deepest module it walks through; the item at its end may be a re-export, and the dependency is
still on the module that re-exports it. A parent's `pub use child::Item` alone is no
dependency on the child (it only offers the child's item); the parent depends on the child
when its own code uses the item. Declaring a child module (`mod x;`) is no dependency either.

A module and its own children count like any two modules: a child that uses its parent's items
while the parent uses the child's is a circle. Every strongly connected component of more than
one module is a cycle; each is listed with the dependencies that make it up and where they are
written, and the script exits with status 1. With --edges it first prints every dependency it
found.
"""
import bisect
import os
import re
import sys
from dataclasses import dataclass, field

IDENT = r"(?:r#)?[A-Za-z_][A-Za-z0-9_]*"
TEST_FILE_NAMES = ("tests.rs", "test_support.rs")


RAW_STRING = re.compile(r"(?:b|c)?r(#*)\"")
PLAIN_RUN = re.compile(r"[^/\"'bcr]+|.", re.S)
WORD_CHAR = re.compile(r"\w")


def strip_comments_and_literals(text):
    """`text` with comments, string and character literals replaced by spaces, newlines kept."""
    out = []
    i, n = 0, len(text)

    def blank(s):
        return re.sub(r"[^\n]", " ", s)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(blank(text[i:j]))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(blank(text[i:j]))
            i = j
        elif (m := RAW_STRING.match(text, i)) and (i == 0 or not WORD_CHAR.match(text[i - 1])):
            end = text.find('"' + m.group(1), m.end())
            j = n if end < 0 else end + 1 + len(m.group(1))
            out.append(blank(text[i:j]))
            i = j
        elif c == '"' or (c in "bc" and text.startswith('"', i + 1) and (i == 0 or not WORD_CHAR.match(text[i - 1]))):
            j = text.index('"', i) + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j += 1
            out.append(blank(text[i:j]))
            i = j
        elif c == "'" or (c == "b" and text.startswith("'", i + 1) and (i == 0 or not WORD_CHAR.match(text[i - 1]))):
            q = text.index("'", i)
            if text.startswith("\\", q + 1):
                j = q + 1
                while j < n and text[j] != "'":
                    j += 2 if text[j] == "\\" else 1
                j += 1
            elif q + 2 < n and text[q + 2] == "'":
                j = q + 3
            else:
                # A lifetime or a label.
                out.append(text[i : q + 1])
                i = q + 1
                continue
            out.append(blank(text[i:j]))
            i = j
        else:
            m = PLAIN_RUN.match(text, i)
            out.append(m.group(0))
            i = m.end()
    return "".join(out)


OPEN, CLOSE = "([{", ")]}"
ATTRIBUTE_START = re.compile(r"\s*#\s*!?\s*\[")
# An item declared by a keyword: it ends with `;` or a block, and may hold commas (`fn f<A, B>`).
KEYWORD_ITEM = re.compile(
    r"\s*(?:pub\s*(?:\([^)]*\))?\s*)?(?:(?:const|async|unsafe|extern|default)\s+)*"
    r"(?:fn|mod|use|impl|struct|enum|union|trait|type|const|static|macro_rules|let|extern)\b"
)


def item_end(code, start):
    """End of the item that starts at `start` (after its attribute): after its `;`, or after the
    block of its first top-level `{`, or, for a field, variant or arm, before the comma or
    closing bracket that ends the list it stands in."""
    i, n = start, len(code)
    while m := ATTRIBUTE_START.match(code, i):
        i = matching_close(code, m.end() - 1) + 1
    keyword_item = KEYWORD_ITEM.match(code, i) is not None
    depth = 0
    while i < n:
        c = code[i]
        if c in OPEN:
            if c == "{" and depth == 0:
                return matching_close(code, i) + 1
            depth += 1
        elif c in CLOSE:
            if depth == 0:
                return i
            depth -= 1
        elif c == ";" and depth == 0:
            return i + 1
        elif c == "," and depth == 0 and not keyword_item:
            return i
        i += 1
    return n


def matching_close(code, i):
    depth = 0
    for j in range(i, len(code)):
        if code[j] in OPEN:
            depth += 1
        elif code[j] in CLOSE:
            depth -= 1
            if depth == 0:
                return j
    return len(code) - 1


CFG_TEST = re.compile(r"#\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]")


def drop_test_items(code):
    """`code` with every `#[cfg(test)]` item blanked (newlines kept)."""
    while m := CFG_TEST.search(code):
        end = item_end(code, m.end())
        code = code[: m.start()] + re.sub(r"[^\n]", " ", code[m.start() : end]) + code[end:]
    return code


def is_test_file(path, src):
    rel = os.path.relpath(path, src).split(os.sep)
    return rel[-1] in TEST_FILE_NAMES or "tests" in rel[:-1]


@dataclass(eq=False)
class Module:
    name: str  # what the report calls it
    path: tuple  # segments from the crate root
    file: str
    code: str  # the file's code, test items and literals blanked; shared by its inline modules
    span: tuple  # (start, end) of the module's own text in `code`
    parent: "Module" = None
    children: dict = field(default_factory=dict)
    # Where children declared with `mod x;` are looked for.
    child_dir: str = ""
    # Inline modules inside the span, whose text is not this module's.
    inline: list = field(default_factory=list)
    raw: str = ""  # the file's text as written (for `#[path = "..."]`, a string literal)

    def is_inline(self):
        return self.parent is not None and self.parent.file == self.file


MOD_DECL = re.compile(
    r"((?:#\s*\[[^\]]*\]\s*)*)(?<![\w$])(?:pub\s*(?:\([^)]*\))?\s*)?(?<![\w$])mod\s+(" + IDENT + r")\s*([;{])"
)
PATH_ATTR = re.compile(r"#\s*\[\s*path\s*=\s*\"([^\"]*)\"\s*\]")


def load_module(name, path, file, parent, child_dir, src, modules, problems):
    text = open(file, encoding="utf-8").read()
    code = strip_comments_and_literals(text)
    if re.match(r"\s*#!\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]", code):
        return None
    code = drop_test_items(code)
    module = Module(name, path, file, code, (0, len(code)), parent, child_dir=child_dir, raw=text)
    modules.append(module)
    read_children(module, src, modules, problems)
    return module


def read_children(module, src, modules, problems):
    code, raw = module.code, module.raw
    start, end = module.span
    i = start
    while m := MOD_DECL.search(code, i, end):
        i = m.end()
        if any(s <= m.start() < e for s, e in module.inline):
            continue
        child = m.group(2).removeprefix("r#")
        if m.group(3) == "{":
            close = matching_close(code, m.end() - 1)
            sub = Module(
                f"{module.name}::{child}",
                module.path + (child,),
                module.file,
                code,
                (m.end(), close),
                module,
                child_dir=os.path.join(module.child_dir, child),
                raw=raw,
            )
            module.inline.append(sub.span)
            module.children[child] = sub
            modules.append(sub)
            read_children(sub, src, modules, problems)
            i = close + 1
            continue
        attrs = raw[m.start(1) : m.end(1)]
        p = PATH_ATTR.search(attrs)
        if p:
            # Relative to the file's directory; inside inline modules, to where their children go.
            base = module.child_dir if module.is_inline() else os.path.dirname(module.file)
            file = os.path.normpath(os.path.join(base, p.group(1)))
            # A file reached through #[path] looks for its own children beside it.
            child_dir = os.path.dirname(file)
        else:
            candidates = [os.path.join(module.child_dir, child + ".rs"), os.path.join(module.child_dir, child, "mod.rs")]
            file = next((c for c in candidates if os.path.exists(c)), None)
            if file is None:
                problems.append(f"{module.name}: no file for `mod {child};` (looked for {' or '.join(candidates)})")
                continue
            child_dir = os.path.dirname(file) if file.endswith("mod.rs") else file[: -len(".rs")]
        if not os.path.exists(file):
            problems.append(f"{module.name}: no file {file} for `mod {child};`")
            continue
        if is_test_file(file, src):
            continue
        loaded = load_module(rel(file), module.path + (child,), file, module, child_dir, src, modules, problems)
        if loaded is not None:
            module.children[child] = loaded


ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rel(path):
    return os.path.relpath(path, ROOT)


USE = re.compile(r"(?<![\w$])(pub\s*(?:\([^)]*\))?\s*)?use\s+([^;]*);")
USE_TOKEN = re.compile(r"\s*(::|\{|\}|,|\*|" + IDENT + r")")


def parse_use_tree(body):
    """The paths of a use tree: a list of (segments, name bound or None for a glob)."""
    tokens = USE_TOKEN.findall(body)
    pos = 0

    def peek():
        return tokens[pos] if pos < len(tokens) else None

    def take():
        nonlocal pos
        pos += 1
        return tokens[pos - 1]

    def tree(prefix):
        out = []
        segs = list(prefix)
        if peek() == "::":  # a leading `::`: an external crate
            take()
            segs.append("::")
        while True:
            t = peek()
            if t == "{":
                take()
                while peek() not in ("}", None):
                    out += tree(segs)
                    if peek() == ",":
                        take()
                take()
                return out
            if t == "*":
                take()
                return out + [(segs, None)]
            if t is None:
                return out
            segs = segs + [take().removeprefix("r#")]
            if peek() == "::":
                take()
                continue
            bound = segs[-1]
            if peek() == "as":
                take()
                bound = take()
            if segs[-1] == "self":
                segs = segs[:-1]
                if bound == "self":
                    bound = segs[-1]
            return out + [(segs, bound)]

    return tree([])


@dataclass
class Ref:
    module: Module  # where it is written
    target: Module
    line: int
    text: str


def resolve(module, segs, aliases):
    """The module the path `segs` written in `module` walks down to (None: outside the crate,
    or not through a module), and how many segments that took."""
    if not segs:
        return None, 0
    s0 = segs[0]
    if s0 == "crate":
        m = module
        while m.parent is not None:
            m = m.parent
        i = 1
    elif s0 == "super":
        m, i = module, 0
        while i < len(segs) and segs[i] == "super":
            m = m.parent
            i += 1
            if m is None:
                return None, 0
    elif s0 == "self":
        m, i = module, 1
    elif s0 in aliases:
        m, i = aliases[s0], 1
        if m is None:
            return None, 0
    elif s0 in module.children:
        m, i = module.children[s0], 1
    else:
        return None, 0
    while i < len(segs) and segs[i] in m.children:
        m = m.children[segs[i]]
        i += 1
    return m, i


def is_descendant(m, ancestor):
    while m is not None:
        m = m.parent
        if m is ancestor:
            return True
    return False


PATH = re.compile(r"(?<![\w$:])(" + IDENT + r"(?:\s*::\s*" + IDENT + r")+)")
VISIBILITY_IN = re.compile(r"pub\s*\(\s*in\s+[^)]*\)")


def references(module):
    """Every dependency `module` has, as Refs."""
    code = module.code
    start, end = module.span
    # The module's own text: its span without the inline modules inside it.
    own = list(code[start:end])
    for s, e in module.inline:
        own[s - start : e - start] = re.sub(r"[^\n]", " ", code[s:e])
    own = "".join(own)
    own = VISIBILITY_IN.sub(lambda m: " " * len(m.group(0)), own)
    newlines = [i for i, c in enumerate(code) if c == "\n"]

    def line_of(offset):
        return bisect.bisect_right(newlines, start + offset) + 1

    refs = []
    aliases = {}  # a name a `use` binds -> the module it names (None: not a crate module)
    reexports = []  # (name, child module, line): a parent's `pub use` of a descendant's item
    uses = list(USE.finditer(own))
    # First the names every use binds; twice, so a use may go through a name a later one binds.
    trees = [(m, parse_use_tree(m.group(2))) for m in uses]
    for _ in range(2):
        for m, paths in trees:
            for segs, bound in paths:
                if bound is None or segs[:1] == ["::"]:
                    if bound is not None:
                        aliases[bound] = None
                    continue
                target, taken = resolve(module, segs, aliases)
                aliases[bound] = target if target is not None and taken == len(segs) else None
    for m, paths in trees:
        line = line_of(m.start())
        text = " ".join(m.group(0).split())
        for segs, bound in paths:
            if segs[:1] == ["::"]:
                continue
            target, _ = resolve(module, segs, aliases)
            if target is None or target is module:
                continue
            if m.group(1) and is_descendant(target, module):
                if bound is not None:
                    reexports.append((bound, target, line))
                continue
            refs.append(Ref(module, target, line, text))
    own = USE.sub(lambda m: re.sub(r"[^\n]", " ", m.group(0)), own)
    for m in PATH.finditer(own):
        segs = [s.strip().removeprefix("r#") for s in m.group(1).split("::")]
        target, _ = resolve(module, segs, aliases)
        if target is None or target is module:
            continue
        refs.append(Ref(module, target, line_of(m.start()), "".join(m.group(1).split())))
    for name, target, line in reexports:
        for m in re.finditer(r"(?<![\w$])" + re.escape(name) + r"(?!\w)", own):
            refs.append(Ref(module, target, line_of(m.start()), f"{name} (re-exported at line {line})"))
            break
    return refs


def cycles(nodes, edges):
    """Strongly connected components of more than one node (Tarjan)."""
    index, low, on_stack, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges.get(v, ()), key=lambda m: m.name):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w is v:
                    break
            if len(component) > 1:
                out.append(sorted(component, key=lambda m: m.name))

    for v in sorted(nodes, key=lambda m: m.name):
        if v not in index:
            visit(v)
    return sorted(out, key=lambda c: c[0].name)


def main():
    sys.setrecursionlimit(10000)
    src = os.path.join(ROOT, "src")
    modules, problems = [], []
    for root in ("lib.rs", "main.rs", "mps2_an386.rs"):
        file = os.path.join(src, root)
        if os.path.exists(file):
            load_module(rel(file), (), file, None, src, src, modules, problems)
    for p in problems:
        print(f"acyclic: {p}", file=sys.stderr)

    edges, evidence = {}, {}
    for module in modules:
        for r in references(module):
            edges.setdefault(module, set()).add(r.target)
            evidence.setdefault((module, r.target), []).append(r)

    if "--edges" in sys.argv[1:]:
        for module in sorted(edges, key=lambda m: m.name):
            for target in sorted(edges[module], key=lambda m: m.name):
                first = evidence[(module, target)][0]
                print(f"{module.name} -> {target.name}    line {first.line}: {first.text}")

    found = cycles(modules, edges)
    count = sum(len(t) for t in edges.values())
    if not found:
        print(f"acyclic: {len(modules)} modules, {count} dependencies, no cycle")
        return 1 if problems else 0
    print(f"acyclic: {len(modules)} modules, {count} dependencies, {len(found)} cycle(s):")
    for n, component in enumerate(found, 1):
        members = set(component)
        print(f"\ncycle {n}: {', '.join(m.name for m in component)}")
        pairs = []
        for a in component:
            for b in sorted(edges.get(a, ()), key=lambda m: m.name):
                if b not in members:
                    continue
                first = evidence[(a, b)][0]
                more = len(evidence[(a, b)]) - 1
                where = f"{first.module.name}:{first.line}: {first.text}" + (f" (+{more} more)" if more else "")
                print(f"  {a.name} -> {b.name}    {where}")
                if a.name < b.name and a in edges.get(b, ()):
                    kind = "parent and child" if a.parent is b or b.parent is a else "each other"
                    pairs.append(f"{a.name} <-> {b.name} ({kind})")
        if pairs:
            print("  depend on each other directly:")
            for p in pairs:
                print(f"    {p}")
    return 1


if __name__ == "__main__":
    sys.exit(main())
