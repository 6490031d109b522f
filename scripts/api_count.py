#!/usr/bin/env python3
"""Counts the library's public API two ways (issue 28, item 4).

1. Exported names: every name a `pub use` of the crate root or of a public module (a facade)
   brings in, and every `pub` item (struct, enum, fn, trait, const, static, type, macro) those
   files declare at their top level, public modules reached recursively (`pub mod x;` in its own
   file or `pub mod x { ... }` inline). Modules themselves are not counted (they are listed).
   A name behind `#[cfg(feature = "F")]` is counted under F too, so the default API and the
   `testing` feature's additions can be told apart.
2. Doc pages (`--doc`): `cargo doc --no-deps --all-features` into a fresh directory, then every
   item page (`struct.`, `enum.`, `fn.`, `trait.`, `constant.`, `static.`, `type.`, `macro.`,
   `union.`, `derive.`, `attr.` *.html) and module page (`index.html`) under `tidepool/`: a
   page whose head holds `http-equiv="refresh"` is a redirect stub, the others are real.

Usage: scripts/api_count.py [--list] [--doc [--features F,G]] [--target-dir DIR]   (from the
crate's root; `--features` documents those features instead of all of them)
"""
import os, re, subprocess, sys

ITEM = re.compile(r"^pub\s+(?:unsafe\s+)?(?:async\s+)?(struct|enum|fn|trait|const|static|type|union|macro)\s+([A-Za-z_][A-Za-z0-9_]*)")


def strip_comments(text):
    """The file without comments and string contents (so braces in them do not count)."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            i = n if j < 0 else j + 2
        elif text[i] == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""')
            i = j + 1
        elif text.startswith("r#\"", i):
            j = text.find("\"#", i + 3)
            out.append('""')
            i = n if j < 0 else j + 2
        else:
            out.append(text[i])
            i += 1
    return "".join(out)


def use_leaves(tree, prefix=""):
    """The names a use tree `a::b::{c, d as e, f::{g}}` binds."""
    tree = tree.strip()
    if not tree:
        return []
    brace = tree.find("{")
    if brace < 0:
        parts = [p.strip() for p in tree.split(" as ")]
        if len(parts) == 2:
            return [parts[1]]
        last = parts[0].split("::")[-1].strip()
        if last == "self":
            return [prefix.rstrip(":").split("::")[-1]]
        return [last] if last != "*" else ["*" + parts[0]]
    head, body = tree[:brace], tree[brace + 1:tree.rfind("}")]
    items, depth, cur = [], 0, ""
    for ch in body:
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        if ch == "," and depth == 0:
            items.append(cur)
            cur = ""
        else:
            cur += ch
    items.append(cur)
    names = []
    for item in items:
        if item.strip() == "self":
            names.append(head.rstrip(":").split("::")[-1])
        else:
            names += use_leaves(item, head)
    return names


def closing(text, start, open_ch, close_ch, stop_at=None):
    """The index of the bracket closing the one at or after `start` (or of `stop_at` met at depth
    0 first); len(text) when there is none."""
    j, d = start, 0
    while j < len(text):
        if text[j] == open_ch:
            d += 1
        elif text[j] == close_ch:
            d -= 1
            if d == 0:
                return j
        elif stop_at and text[j] == stop_at and d == 0:
            return j
        j += 1
    return j


def scan(text, path, module, src_dir, feats_above, out, modules):
    """Walks one module's top level: its pub uses, pub items and public submodules."""
    modules.append((module, sorted(feats_above)))
    i, n, depth = 0, len(text), 0
    raw_cfgs = []
    while i < n:
        ch = text[i]
        if ch == "{":
            depth += 1
            i += 1
            continue
        if ch == "}":
            depth -= 1
            i += 1
            continue
        if depth != 0 or ch.isspace():
            i += 1
            continue
        rest = text[i:]
        if rest.startswith("#!["):
            i = text.find("]", i) + 1
            continue
        if rest.startswith("#["):
            j = closing(text, i + 1, "[", "]")
            raw_cfgs.append(text[i:j + 1])
            i = j + 1
            continue
        # One statement or item at this level.
        cfgs, raw_cfgs = raw_cfgs, []
        feats = set(feats_above)
        for a in cfgs:
            if a.startswith("#[cfg("):
                feats |= set(re.findall(r"feat_([A-Za-z0-9_-]+)", a))
                if re.search(r"\bdoctest\b", a):
                    feats.add("<doctest>")
                elif re.search(r"\btest\b", a):
                    feats.add("<test>")
        hidden = any("doc(hidden)" in a for a in cfgs)
        m_use = re.match(r"pub\s+use\s+([^;]*);", rest, re.S)
        m_mod = re.match(r"pub\s+mod\s+([A-Za-z_][A-Za-z0-9_]*)\s*([;{])", rest)
        m_item = ITEM.match(rest)
        if m_use:
            for name in use_leaves(" ".join(m_use.group(1).split())):
                out.append((module, name, sorted(feats), hidden))
            i += m_use.end()
            continue
        if m_mod:
            name, kind = m_mod.group(1), m_mod.group(2)
            sub = f"{module}::{name}"
            if kind == ";":
                base = os.path.dirname(path)
                if os.path.basename(path) not in ("lib.rs", "mod.rs"):
                    base = os.path.join(base, os.path.splitext(os.path.basename(path))[0])
                for cand in (os.path.join(base, name + ".rs"), os.path.join(base, name, "mod.rs")):
                    if os.path.exists(cand):
                        scan(load(cand), cand, sub, src_dir, feats, out, modules)
                        break
                i += m_mod.end()
            else:
                start = i + m_mod.end() - 1
                j = closing(text, start, "{", "}")
                scan(text[start + 1:j], path, sub, src_dir, feats, out, modules)
                i = j + 1
            continue
        if m_item:
            if "<test>" not in feats and "<doctest>" not in feats:
                out.append((module, m_item.group(2), sorted(feats), hidden))
        # Skip to the end of this statement or item: a `;` or a balanced block at this level.
        i = closing(text, i, "{", "}", stop_at=";") + 1


def cfg_tag(m):
    """`#[cfg(feature = "x")]` as `#[cfg(feat_x)]`: its features survive the string blanking."""
    real = m.group(0)
    feats = re.findall(r'feature\s*=\s*"([^"]+)"', real)
    words = [f"feat_{f}" for f in feats]
    if re.search(r"\bdoctest\b", real):
        words.append("doctest")
    elif re.search(r"\btest\b", real) and not feats:
        words.append("test")
    return "#[cfg(" + ",".join(words) + ")]"


def load(path):
    """The file without comments and string contents, cfg attributes kept readable."""
    raw = open(path).read()
    raw = re.sub(r"#\[cfg\((?:[^()]|\([^()]*\))*\)\]", cfg_tag, raw)
    return strip_comments(raw)


def doc_pages(target_dir, features):
    out_dir = os.path.join(target_dir, "doc", "tidepool")
    subprocess.run(["rm", "-rf", out_dir], check=True)
    env = dict(os.environ, CARGO_TARGET_DIR=target_dir)
    chosen = ["--all-features"] if features is None else ["--features", features]
    subprocess.run(["cargo", "doc", "--no-deps", "-q"] + chosen, check=True, env=env)
    real, stub = [], []
    kinds = re.compile(r"^(struct|enum|fn|trait|constant|static|type|macro|union|derive|attr)\..*\.html$")
    for d, _, files in os.walk(out_dir):
        for f in files:
            if kinds.match(f) or f == "index.html":
                p = os.path.join(d, f)
                head = open(p, errors="replace").read(2000)
                (stub if 'http-equiv="refresh"' in head else real).append(os.path.relpath(p, out_dir))
    return sorted(real), sorted(stub)


def main():
    args = sys.argv[1:]
    names, modules = [], []
    scan(load("src/lib.rs"), "src/lib.rs", "tidepool", "src", set(), names, modules)
    names = [n for n in names if "<doctest>" not in n[2] and "<test>" not in n[2]]
    by_module = {}
    for module, name, feats, hidden in names:
        by_module.setdefault(module, []).append((name, feats, hidden))
    all_feats = sorted({f for _, _, fs, _ in names for f in fs})
    print(f"exported names (crate root and public modules): {len(names)}")
    for f in all_feats:
        print(f"  of which behind feature `{f}`: {sum(1 for n in names if f in n[2])}")
    without_testing = [n for n in names if "testing" not in n[2]]
    print(f"  without the `testing` feature: {len(without_testing)}")
    hidden = [n for n in names if n[3]]
    if hidden:
        print(f"  #[doc(hidden)]: {len(hidden)}")
    for module, _ in modules:
        entries = by_module.get(module, [])
        line = f"  {module}: {len(entries)}"
        if "--list" in args:
            line += "  " + " ".join(n + (f"[{','.join(fs)}]" if fs else "") for n, fs, _ in entries)
        print(line)
    if "--doc" in args:
        target = "target"
        if "--target-dir" in args:
            target = args[args.index("--target-dir") + 1]
        features = args[args.index("--features") + 1] if "--features" in args else None
        real, stub = doc_pages(os.path.abspath(target), features)
        how = "--all-features" if features is None else f"--features {features}"
        print(f"doc pages (cargo doc --no-deps {how}): {len(real) + len(stub)}: "
              f"{len(real)} real, {len(stub)} redirect stubs")
        if "--list" in args:
            for p in real:
                print("  " + p)


if __name__ == "__main__":
    main()
