#!/usr/bin/env python3
"""Checks the crate's imports, file by file and folder by folder.

1. Import circles between modules: an edge A -> B when file A names crate::B or super::B outside
   comments and tests; a parent and its own children may use each other.
2. The layers (ARCHITECTURE.md, "The layers"), by top-level folder of src/: a folder never
   imports the folders LAYERS lists for it (any file in it, any depth, `crate::x` or
   `crate::{x, ..}`). The rule that matters most: the play session (src/play/) imports no door
   (src/term/, and the command line src/cli/ with the SSH door src/cli/serve/). The command
   line is the top: no folder but src/cli/ itself imports it (the binary, src/bin/, only calls
   `tidepool::cli::main`). Test files (`tests.rs`,
   `*_tests.rs`, anything under a `tests/` folder) are the harness and may use any layer.
3. The sans-IO core (ARCHITECTURE.md, "The play session"): no file of src/play/ or src/output/
   (the encoders the session calls) names the file system, the environment, /proc, threads,
   sockets, the clock or sleep outside its tests; NO_IO_EXCEPTIONS lists the files that may,
   each with its reason.

Usage: scripts/import_cycles.py src   (prints each problem; exit 1 if any)"""
import os,re,sys

# folder -> the folders it must never import. Lower layers know nothing of the ones above them:
# simulation < rendering < scenes < output encoders < the play session < the doors (the
# terminal door, the command line and its SSH door, src/cli/serve/).
DOORS = {"term", "tty", "cli"}
# The top of the crate: only itself (and the binary, through the public `cli::main`) uses it.
TOP = "cli"
LAYERS = {
    "sim": {"render", "scene", "output", "play"} | DOORS,
    "render": {"scene", "output", "play"} | DOORS,
    "output": {"scene", "play"} | DOORS,
    "scene": {"play"} | DOORS,
    "play": DOORS,
    "encode": {"play"} | DOORS,
    "graphics": {"play"} | DOORS,
    "sea": {"play"} | DOORS,
    "terminal": {"play"} | DOORS,
    "replay": {"play"} | DOORS,
}

# What the sans-IO core never names outside its tests: the file system, the environment, /proc,
# threads (and their sleep), sockets, the standard streams, the clock.
CORE = ("play", "output")
NO_IO = re.compile(r"\bstd::(fs|env|thread|net|process::Command)\b|\bfs::|\benv::|\bFile::|\"/proc|"
                   r"\bInstant::now\b|\bSystemTime\b|\bsleep(_until)?\(|\bstd(in|out|err)\(\)|"
                   r"\bstd::\{[^}]*\b(fs|env|thread|net)\b")
NO_IO_EXCEPTIONS = {
    # kitty's temporary files on disk: the door writes the session's (handed out as data) with
    # it, and a picture written once (`render --out -`, KittyEncoder) writes its own.
    "output/graphics/kitty/files.rs",
    # A test tool (feature `testing` in spirit): decodes what a terminal would read, files too.
    "output/graphics/kitty_decode.rs",
}

def is_test_file(path):
    base=os.path.basename(path)
    return base=="tests.rs" or base.endswith("_tests.rs") or (os.sep+"tests"+os.sep) in path

def io_problems(root):
    """Each line of the sans-IO core that names I/O or the clock: (file, line, text)."""
    problems=[]
    for top in CORE:
        for d,_,fs in os.walk(os.path.join(root, top)):
            for f in fs:
                path=os.path.join(d,f)
                rel=os.path.relpath(path,root).replace(os.sep,"/")
                if not f.endswith(".rs") or is_test_file(path) or rel in NO_IO_EXCEPTIONS: continue
                for n,l in enumerate(code_of(path).split("\n"),1):
                    if NO_IO.search(l): problems.append((path,n,l.strip()))
    return problems

def code_of(path):
    """The file's text without its test module and its comment lines."""
    s=open(path).read()
    s=re.sub(r'#\[cfg\(test\)\]\s*mod tests\s*\{.*', '', s, flags=re.S)
    # Comment lines blanked, not removed, so that line numbers stay the file's.
    return '\n'.join('' if l.strip().startswith('//') else l for l in s.split('\n'))

def crate_roots(code):
    """The top-level modules a file names through `crate::`, with the line of each."""
    found=[]
    for m in re.finditer(r'\bcrate::(\{[^}]*\}|[a-z_0-9]+)', code):
        line=code.count('\n',0,m.start())+1
        names=m.group(1)
        if names.startswith('{'):
            for part in re.split(r'[,{}\s]+', names):
                if part: found.append((part.split('::')[0], line))
        else:
            found.append((names, line))
    return found

def layer_problems(root):
    """Each import that crosses a layer the wrong way: (file, line, folder, imported)."""
    problems=[]
    for d,_,fs in os.walk(root):
        for f in fs:
            if not f.endswith('.rs'): continue
            path=os.path.join(d,f)
            if is_test_file(path): continue
            top=os.path.relpath(path,root).split(os.sep)[0]
            top=top[:-3] if top.endswith('.rs') else top
            forbidden=LAYERS.get(top,set()) | ({TOP} if top not in (TOP, "bin") else set())
            for name,line in crate_roots(code_of(path)):
                if name in forbidden: problems.append((path,line,top,name))
    return problems
def modpath(root, path):
    rel=os.path.relpath(path, root)[:-3]
    parts=rel.split(os.sep)
    if parts[-1] in ("mod","lib","main"): parts=parts[:-1]
    return tuple(parts)
def analyse(root):
    files=[os.path.join(d,f) for d,_,fs in os.walk(root) for f in fs if f.endswith('.rs')]
    mods={modpath(root,f):f for f in files}
    edges={}
    for m,f in mods.items():
        s=code_of(f)
        targets=set()
        for mm in re.finditer(r'\b(crate|super)((?:::[a-z_0-9]+)+)', s):
            base=mm.group(1); path=mm.group(2).split('::')[1:]
            cur=() if base=='crate' else (m[:-1] if not f.endswith(('mod.rs',)) else m[:-1])
            if base=='super': cur=m[:-1]
            full=cur+tuple(path)
            while full and full not in mods: full=full[:-1]
            if full and full!=m: targets.add(full)
        for t in targets:
            # ignore parent/child relations
            if t[:len(m)]==m or m[:len(t)]==t: continue
            edges.setdefault(m,set()).add(t)
    # find cycles (SCCs)
    idx={};low={};st=[];on=set();res=[];c=[0]
    def sc(v):
        idx[v]=low[v]=c[0];c[0]+=1;st.append(v);on.add(v)
        for w in edges.get(v,()):
            if w not in idx: sc(w);low[v]=min(low[v],low[w])
            elif w in on: low[v]=min(low[v],idx[w])
        if low[v]==idx[v]:
            comp=[]
            while True:
                w=st.pop();on.discard(w);comp.append(w)
                if w==v:break
            if len(comp)>1: res.append(comp)
    sys.setrecursionlimit(10000)
    for v in list(mods):
        if v not in idx: sc(v)
    return res
found = False
for root in sys.argv[1:]:
    for comp in analyse(root):
        found = True
        print(root, "import circle:", " <-> ".join(sorted("::".join(c) for c in comp)))
    for path,line,top,name in layer_problems(root):
        found = True
        print(f"{path}:{line}: src/{top}/ imports crate::{name}, a layer above it (ARCHITECTURE.md, The layers)")
    if os.path.isdir(os.path.join(root, "play")):
        for path,line,text in io_problems(root):
            found = True
            print(f"{path}:{line}: the sans-IO core does I/O or reads the clock: `{text}` (the door does it; ARCHITECTURE.md)")
sys.exit(1 if found else 0)
