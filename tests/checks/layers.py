#!/usr/bin/env python3
"""The library's layers, from the built objects and the sources: port/ (kernels, the SIMD
resolver) is the lower layer and never reaches up into src/ (no symbol a port/ object needs is
defined by a src/ object, no port/ file includes a src/ header), and no circle runs between the
objects (call graph: an object's undefined symbols against the others' definitions) or between
the headers (quoted includes). Prints what it finds; exits 1 on any arrow up or circle.
usage: layers.py BUILD [NM]"""
import glob
import os
import re
import subprocess
import sys

build = sys.argv[1] if len(sys.argv) > 1 else "build"
nm = sys.argv[2] if len(sys.argv) > 2 else "nm"
problems = []


def symbols(obj, undefined):
    args = [nm, "-u", obj] if undefined else [nm, "--defined-only", "-g", obj]
    out = subprocess.run(args, capture_output=True, text=True, check=True).stdout
    return {line.split()[-1] for line in out.splitlines() if line.strip()}


objs = [os.path.join(build, "obj", c[:-2] + ".o") for c in sorted(glob.glob("src/*.c") + glob.glob("port/*.c"))]
objs = [o for o in objs if os.path.exists(o)]
if not objs:
    sys.exit("layers: no objects under %s/obj" % build)
name = {o: os.path.relpath(o, os.path.join(build, "obj")) for o in objs}
owner = {}
for o in objs:
    for s in symbols(o, False):
        owner[s] = o
calls = {}
for o in objs:
    needs = {}
    for s in symbols(o, True):
        if s in owner and owner[s] != o:
            needs.setdefault(owner[s], []).append(s)
    calls[o] = needs
    if name[o].startswith("port/"):
        for target, syms in needs.items():
            if name[target].startswith("src/"):
                problems.append("%s calls up into %s: %s" % (name[o], name[target], " ".join(sorted(syms))))


def circles(graph):
    """every elementary circle found by a depth-first search (one per back edge)"""
    found, state, stack = [], {}, []

    def visit(v):
        state[v] = 1
        stack.append(v)
        for w in sorted(graph.get(v, ())):
            if state.get(w) == 1:
                found.append(stack[stack.index(w):] + [w])
            elif not state.get(w):
                visit(w)
        stack.pop()
        state[v] = 2

    for v in sorted(graph):
        if not state.get(v):
            visit(v)
    return found


for c in circles({name[o]: {name[t] for t in calls[o]} for o in objs}):
    problems.append("call circle: " + " -> ".join(c))

includes = {}
for path in sorted(glob.glob("src/*.[ch]") + glob.glob("port/*.[ch]")):
    text = open(path, encoding="utf-8").read()
    incs = re.findall(r'^\s*#\s*include\s+"([^"]+)"', text, re.M)
    includes[path] = set()
    for inc in incs:
        base = os.path.basename(inc)
        for d in (os.path.dirname(path), "port", "include", "src"):
            cand = os.path.join(d, base)
            if os.path.exists(cand) and (d != "src" or path.startswith("src/")):
                includes[path].add(os.path.normpath(cand))
                break
        if path.startswith("port/") and (inc.startswith("../src") or os.path.exists(os.path.join("src", base))
                                         and not os.path.exists(os.path.join("port", base))):
            problems.append("%s includes a src/ header: %s" % (path, inc))
for c in circles({k: {v for v in vs if v.endswith(".h")} for k, vs in includes.items()}):
    problems.append("include circle: " + " -> ".join(c))

arrows = sum(len(v) for v in calls.values())
print("layers: %d objects, %d arrows between them, %d problems" % (len(objs), arrows, len(problems)))
for p in problems:
    print("  " + p)
sys.exit(1 if problems else 0)
