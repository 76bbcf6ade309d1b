#!/usr/bin/env python3
"""Worst-case stack of every public libhome function, from gcc's per-function frame sizes
(-fstack-usage, .su) summed along the call graph (-fcallgraph-info=su, .ci).

    python3 tests/checks/stack_usage.py [--limit BYTES] OBJ_DIR

Public functions are the graph's home_* nodes (home__* are internal). The graph has no cycles
(the library has no recursion; a cycle is reported as an error). Indirect calls are resolved
conservatively (see indirect_targets: any SIMD kernel or library callback), so a new kernel or
callback is counted without listing it. Calls into libc/libm (memset, sincos, exp, ...)
are charged EXTERNAL_BYTES each; the painted-stack test (home-hardening-tests stack_painted)
measures the real total, libc included. The user's clock hook runs on the caller's stack and
is not counted. Exit status 1 if any public function exceeds the limit or the graph is unusable.
"""
import argparse
import fnmatch
import glob
import os
import re
import subprocess
import sys

# Bytes charged for one call into libc/libm (leaf routines: memset, memcpy, sincos, exp, sqrt,
# lround, getenv, strcmp). glibc's x86-64 and aarch64 versions use well under this.
EXTERNAL_BYTES = 512

# Indirect calls, resolved conservatively: the caller's clock hook runs on the caller's stack
# and is not counted; a SIMD kernel's indirect calls are the scalar kernels (port/*scalar.c); any
# other indirect call may reach any kernel in port/ or either library callback. Listed callers
# first (caller pattern -> callee patterns), then the defaults.
CLOCK_HOOK_CALLERS = ["home__now", "home_stab_push"]
CALLBACKS = ["src/pipeline.c:on_row", "src/homography.c:line_residual"]
# their one indirect call: a kernel (the extremum scan, the smoothing along r and theta, the warp)
INDIRECT = {"home__extremum_candidates": ["port/*"], "home__smooth_r": ["port/*"],
            "home__smooth_theta": ["port/*"], "home__warp_row": ["port/*"]}

NODE = re.compile(r'node: \{ title: "([^"]+)" label: "([^"]*)"( shape : ellipse)?')
EDGE = re.compile(r'edge: \{ sourcename: "([^"]+)" targetname: "([^"]+)"')
BYTES = re.compile(r"\\n(\d+) bytes \(([a-z,]+)\)")


def load(obj_dir):
    frames, edges, external = {}, {}, set()
    files = sorted(glob.glob(os.path.join(obj_dir, "**", "*.ci"), recursive=True))
    if not files:
        sys.exit("stack_usage: no .ci files under %s (build with -fstack-usage -fcallgraph-info=su)" % obj_dir)
    for path in files:
        for line in open(path):
            m = NODE.search(line)
            if m:
                title, label, ellipse = m.groups()
                b = BYTES.search(label)
                if b:
                    if "dynamic" in b.group(2) and "bounded" not in b.group(2):
                        sys.exit("stack_usage: %s has an unbounded dynamic frame (VLA/alloca)" % title)
                    frames[title] = int(b.group(1))
                elif ellipse and title != "__indirect_call":
                    external.add(title)
                continue
            m = EDGE.search(line)
            if m:
                edges.setdefault(m.group(1), []).append(m.group(2))
    return frames, edges, external - set(frames)


def indirect_targets(caller, frames):
    if caller in CLOCK_HOOK_CALLERS:
        return []
    for pattern, callees in INDIRECT.items():
        if fnmatch.fnmatchcase(caller, pattern):
            return [f for f in frames if f != caller and any(fnmatch.fnmatchcase(f, c) for c in callees)]
    kernels = [f for f in frames if f.startswith("port/") and "dispatch" not in f]
    if caller.startswith("port/") or re.search(r"_(sse|avx2|neon)$", caller):
        found = [f for f in kernels if "scalar.c:" in f]
    else:
        found = kernels + [f for f in frames if f in CALLBACKS]
    if not found:
        sys.exit("stack_usage: no targets for the indirect call in %s" % caller)
    return [f for f in found if f != caller]


def worst(fn, frames, edges, external, memo, stack):
    """(bytes, path) of the deepest call chain starting at fn."""
    if fn in memo:
        return memo[fn]
    if fn in stack:
        sys.exit("stack_usage: recursion through %s" % " -> ".join(stack + [fn]))
    if fn in external:
        return EXTERNAL_BYTES, ["%s(libc)" % fn]
    if fn not in frames:
        sys.exit("stack_usage: no frame size for %s" % fn)
    best = (0, [])
    for callee in edges.get(fn, []):
        for target in (indirect_targets(fn, frames) if callee == "__indirect_call" else [callee]):
            sub = worst(target, frames, edges, external, memo, stack + [fn])
            if sub[0] > best[0]:
                best = sub
    memo[fn] = (frames[fn] + best[0], [fn] + best[1])
    return memo[fn]


def section_sizes(lib, objdump):
    """Bytes per section kind summed over the archive's members (objdump -h)."""
    kinds = {"text": 0, "rodata": 0, "data.rel.ro": 0, "data": 0, "bss": 0}
    out = subprocess.run([objdump, "-h", lib], check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        f = line.split()
        if len(f) < 3 or not f[0].isdigit() or not f[1].startswith("."):
            continue
        name, size = f[1], int(f[2], 16)
        for kind in ("data.rel.ro", "text", "rodata", "data", "bss"):
            if name == "." + kind or name.startswith("." + kind + "."):
                kinds[kind] += size
                break
    return kinds


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--limit", type=int, default=16384)
    ap.add_argument("--lib", help="also print the library's section sizes (objdump -h)")
    ap.add_argument("--objdump", default="objdump")
    ap.add_argument("obj_dir")
    args = ap.parse_args()
    if args.lib:
        sizes = section_sizes(args.lib, args.objdump)
        print("library sections (bytes): " + ", ".join(".%s %d" % kv for kv in sizes.items()))
    frames, edges, external = load(args.obj_dir)
    public = sorted(f for f in frames if f.startswith("home_") and not f.startswith("home__"))
    if not public:
        sys.exit("stack_usage: no public functions found")
    memo, over = {}, 0
    print("%-28s %7s  deepest chain (own frames; libc calls charged %d B)" % ("function", "bytes", EXTERNAL_BYTES))
    for fn in public:
        total, path = worst(fn, frames, edges, external, memo, [])
        over += total > args.limit
        chain = " > ".join(p.split(":")[-1] for p in path)
        print("%-28s %7d  %s%s" % (fn, total, chain, "  OVER LIMIT" if total > args.limit else ""))
    print("stack: %d public functions, worst %d bytes, limit %d" % (
        len(public), max(memo[f][0] for f in public), args.limit))
    return 1 if over else 0


if __name__ == "__main__":
    sys.exit(main())
