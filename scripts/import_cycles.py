#!/usr/bin/env python3
"""Finds import circles between the crate's modules: an edge A -> B when file A names crate::B or
super::B outside comments and tests; a parent and its own children may use each other.
Usage: scripts/import_cycles.py src src/bin/tidepool   (prints each circle; exit 1 if any)"""
import os,re,sys
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
        s=open(f).read()
        s=re.sub(r'#\[cfg\(test\)\]\s*mod tests\s*\{.*', '', s, flags=re.S)
        s='\n'.join(l for l in s.split('\n') if not l.strip().startswith('//'))
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
sys.exit(1 if found else 0)
