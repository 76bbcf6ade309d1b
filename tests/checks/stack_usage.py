#!/usr/bin/env python3
"""Worst-case stack of every public libhome function, from gcc's per-function frame sizes
(-fstack-usage, .su) summed along the call graph (-fcallgraph-info=su, .ci).

    python3 tests/checks/stack_usage.py [--limit BYTES] OBJ_DIR

Public functions are the graph's home_* nodes (home__* are internal). The graph has no cycles
(the library has no recursion; a cycle is reported as an error). Indirect calls are resolved by
the table below; an indirect call from a function it does not cover is an error, so a new
callback or kernel cannot slip past the bound. Calls into libc/libm (memset, sincos, exp, ...)
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

# caller pattern -> callee patterns of its indirect calls (node titles: "file:name" for static
# functions, "name" for external ones)
INDIRECT = {
    "home__hough_stream": ["src/pipeline.c:on_row", "port/*:radon_blocks_*", "port/*:smooth_cols_*"],
    "home__lm_solve": ["src/homography.c:line_residual"],
    "src/lm.c:total_cost": ["src/homography.c:line_residual"],
    "home__smooth_r": ["port/*:smooth_row_*"],
    "src/match.c:best_match": ["port/*:nearest2_l1_*"],
    "port/*:smooth_row_*": ["port/scalar.c:smooth_row_scalar"],   # SIMD tails
    "port/*:smooth_cols_*": ["port/scalar.c:smooth_cols_scalar"],
    "home__now": [],                                                # the caller's clock hook
}

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
    for pattern, callees in INDIRECT.items():
        if fnmatch.fnmatchcase(caller, pattern):
            found = [f for f in frames if f != caller and any(fnmatch.fnmatchcase(f, c) for c in callees)]
            if callees and not found:
                sys.exit("stack_usage: no function matches the indirect targets of %s: %s" % (caller, callees))
            return found
    sys.exit("stack_usage: unresolved indirect call in %s: add its targets to INDIRECT" % caller)


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
