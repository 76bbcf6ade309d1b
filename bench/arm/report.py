#!/usr/bin/env python3
"""The table of make bench-arm, from the runs bench/arm/count.sh made.

Instructions: each run's plugin output lists every translated block (start address, its
instructions, executions). A block belongs to the function whose symbol precedes it (nm) and to
the object file whose .text holds it (the link map); function and object give the stage. Per
frame: the difference of the two runs of a task divided by the frames between them.

Time: each hot block (those that make up COVER of a frame's instructions) is given to llvm-mca
(-mcpu=cortex-a72, and cortex-a76) as a loop body of that block alone; its cycles per execution
times its executions per frame are the block's cycles. The rest of a stage runs at the IPC of
its analysed blocks. An estimate: llvm-mca assumes every load hits L1 and every branch is
predicted, and LLVM (14 to 16) schedules cortex-a76 with its Cortex-A57 model, as it does the
A72, so the A76 figure is the A72's cycles at the A76's clock (its wider core would be faster).
"""
import argparse
import bisect
import collections
import json
import os
import re
import subprocess
import sys

COVER = 0.95          # share of each frame's instructions given to llvm-mca
MAX_BLOCKS = 400      # and at most this many blocks per program
CLOCKS = [("A72@1.5", "cortex-a72", 1.5), ("A72@1.8", "cortex-a72", 1.8), ("A76@2.4", "cortex-a76", 2.4)]
STAGES = ["hough", "extrema", "describe", "match", "homography", "refine", "warp", "stab",
          "lib-other", "libc", "tool"]
LIB_STAGES = STAGES[:9]
ARCH = {
    "aarch64": {"tools": "aarch64-linux-gnu-", "triple": "aarch64-linux-gnu", "thumb": False, "cpus": {}},
    # Debian's armhf gcc emits Thumb-2; LLVM's 32-bit ARM backend has no cortex-a76 model at all
    "armv7": {"tools": "arm-linux-gnueabihf-", "triple": "thumbv7-linux-gnueabihf", "thumb": True,
              "cpus": {"cortex-a76": "cortex-a72"}},
}
TASKS = {"video": ("home-arm-frames", 1, 3), "stab": ("home-stab", 2, 6)}

# library objects by name; the kernel files (port/) by function
OBJECT_STAGE = [
    (r"^(hough|smooth|gradient)\.o$", "hough"),
    (r"^extrema\.o$", "extrema"),
    (r"^describe\.o$", "describe"),
    (r"^match\.o$", "match"),
    (r"^(homography|lm|model|line_fit_\w+)\.o$", "homography"),
    (r"^refine\w*\.o$", "refine"),
    (r"^(warp|stab_(scalar|neon|sse|avx2))\.o$", "warp"),
    (r"^(stabilise|stab_\w+)\.o$", "stab"),
]
FUNCTION_STAGE = [
    (r"radon|line_ends|resample|smooth|box_down|accumulate_stats|quantise_row", "hough"),
    (r"extrem|on_row", "extrema"),
    (r"fill_keypoints|describe", "describe"),
    (r"nearest2", "match"),
]


def stage_of(obj, func, in_lib):
    if not in_lib:
        return "tool" if re.match(r"^(frames|home-stab|y4m|stab_png|stab_clip|synth|pgm)\.o$", obj) else "libc"
    if obj.startswith(("home_", "pipeline")) or obj in ("dispatch.o", "context.o", "config.o", "common.o"):
        for pat, stage in FUNCTION_STAGE:
            if re.search(pat, func):
                return stage
    for pat, stage in OBJECT_STAGE:
        if re.match(pat, obj):
            return stage
    return "lib-other"


class Program:
    """A static binary with its link map: block address -> (object, function, stage)."""

    def __init__(self, out, arch, prog):
        self.arch = arch
        self.path = os.path.join(out, arch, "bin", prog)
        tools = ARCH[arch]["tools"]
        text = open(os.path.join(out, arch, prog + ".map")).read()
        secs = []
        for m in re.finditer(r"^ (\.text[\w.]*)\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S+)", text, re.M):
            start, size = int(m.group(2), 16), int(m.group(3), 16)
            if size:
                secs.append((start, start + size, m.group(4)))
        secs.sort()
        self.secs, self.sec_starts = secs, [s[0] for s in secs]
        syms = []
        nm = subprocess.run([tools + "nm", "-n", "--defined-only", self.path], capture_output=True,
                            text=True, check=True).stdout
        for line in nm.splitlines():
            f = line.split()
            if len(f) >= 3 and f[1] in "tTwWiI" and not f[2].startswith("$"):
                syms.append((int(f[0], 16), f[2]))
        self.syms, self.sym_starts = syms, [s[0] for s in syms]
        self.cache = {}

    def where(self, vaddr):
        if vaddr in self.cache:
            return self.cache[vaddr]
        i = bisect.bisect_right(self.sym_starts, vaddr) - 1
        func = self.syms[i][1] if i >= 0 else "?"
        j = bisect.bisect_right(self.sec_starts, vaddr) - 1
        src = self.secs[j][2] if j >= 0 and vaddr < self.secs[j][1] else "?"
        in_lib = "libhome.a(" in src
        obj = re.sub(r".*\((.*)\)$", r"\1", src).split("/")[-1]
        r = (obj, func, stage_of(obj, func, in_lib))
        self.cache[vaddr] = r
        return r


def load_blocks(path):
    blocks = collections.Counter()
    for line in open(path):
        v, n, e = line.split()[:3]
        blocks[(int(v, 16), int(n))] += int(e)
    return blocks


def per_frame(out, arch, task, size):
    prog, lo, hi = TASKS[task]
    a = load_blocks(os.path.join(out, "%s-%s-%s-%d.blocks" % (arch, task, size, lo)))
    b = load_blocks(os.path.join(out, "%s-%s-%s-%d.blocks" % (arch, task, size, hi)))
    frames = hi - lo
    return {k: (b.get(k, 0) - a.get(k, 0)) / frames for k in set(a) | set(b)}


def block_asm(prog, vaddr, n):
    """The block's n instructions as assembly llvm-mca reads (branch targets -> a local label)."""
    tools, thumb = ARCH[prog.arch]["tools"], ARCH[prog.arch]["thumb"]
    dis = subprocess.run([tools + "objdump", "-d", "--no-show-raw-insn",
                          "--start-address=0x%x" % vaddr, "--stop-address=0x%x" % (vaddr + 4 * n),
                          prog.path], capture_output=True, text=True, check=True).stdout
    lines = []
    for line in dis.splitlines():
        m = re.match(r"^\s*[0-9a-f]+:\s+(.*)$", line)
        if not m:
            continue
        ins = re.sub(r"\s*(//|@|;).*$", "", m.group(1)).strip()
        ins = re.sub(r"\b(0x)?[0-9a-f]+ <[^>]*>", ".Lb", ins)
        if ins:
            lines.append(ins)
        if len(lines) == n:
            break
    head = [".syntax unified", ".thumb"] if thumb else []
    return head + [".Lb:"] + lines


MCA_CACHE = {}


def mca_cycles(prog, vaddr, n, cpu):
    """Cycles per execution of the block in a steady loop, or None when llvm-mca rejects it."""
    key = (prog.arch, prog.path, vaddr, n, cpu)
    if key in MCA_CACHE:
        return MCA_CACHE[key]
    asm = block_asm(prog, vaddr, n)
    result = None
    for _ in range(6):  # drop lines llvm's assembler rejects (GNU-only spellings), a few at most
        r = subprocess.run(["llvm-mca", "-mtriple=" + ARCH[prog.arch]["triple"],
                            "-mcpu=" + ARCH[prog.arch]["cpus"].get(cpu, cpu),
                            "-iterations=200", "-"], input="\n".join(asm) + "\n",
                           capture_output=True, text=True)
        m = re.search(r"Total Cycles:\s+(\d+)", r.stdout)
        if r.returncode == 0 and m:
            result = int(m.group(1)) / 200.0
            break
        bad = sorted({int(x) for x in re.findall(r"<stdin>:(\d+):\d+: error", r.stderr)}, reverse=True)
        if not bad:
            break
        for ln in bad:
            if 0 < ln <= len(asm) and not asm[ln - 1].startswith("."):
                asm.pop(ln - 1)
    MCA_CACHE[key] = result
    return result


def block_end(prog, vaddr, n):
    """The address after the block's n instructions (Thumb-2 mixes 2- and 4-byte ones)."""
    dis = subprocess.run([ARCH[prog.arch]["tools"] + "objdump", "-d", "--no-show-raw-insn",
                          "--start-address=0x%x" % vaddr, "--stop-address=0x%x" % (vaddr + 4 * n + 4),
                          prog.path], capture_output=True, text=True, check=True).stdout
    addrs = [int(m.group(1), 16) for m in re.finditer(r"^\s*([0-9a-f]+):\s+\S", dis, re.M)]
    return addrs[n] if len(addrs) > n else vaddr + 4 * n


def join_page_splits(prog, pf):
    """qemu ends a translated block at a 4 KiB page boundary, so a loop that crosses one comes as
    two blocks; given to llvm-mca apart, each would be scheduled as a loop of its own (the tail of
    a loop body as a tight loop: far more cycles). A block that ends where a page starts is joined
    with the page's first block for as many executions as it has (the page's block may also be
    entered from elsewhere: those executions stay its own)."""
    at_page = {v: n for (v, n), e in pf.items() if v % 4096 == 0 and e > 0}
    if not at_page:
        return pf
    out = dict(pf)
    for (u, m), e in pf.items():
        page = (u // 4096 + 1) * 4096
        n = at_page.get(page)
        if e <= 0 or n is None or u % 4096 == 0 or u + 4 * m < page - 2 * m:
            continue
        tail_e = out.get((page, n), 0)
        if tail_e + 1e-9 < e or block_end(prog, u, m) != page:
            continue
        del out[(u, m)]
        out[(page, n)] = tail_e - e
        out[(u, m + n)] = out.get((u, m + n), 0) + e
    return out


def analyse(out, arch, task, size, progs):
    prog = progs[(arch, TASKS[task][0])]
    pf = join_page_splits(prog, per_frame(out, arch, task, size))
    stage_insns = collections.Counter()
    func_insns = collections.Counter()
    for (v, n), e in pf.items():
        obj, func, stage = prog.where(v)
        stage_insns[stage] += n * e
        func_insns[(stage, func)] += n * e
    total = sum(stage_insns.values())
    # llvm-mca on the hottest blocks
    hot = sorted(((n * e, v, n, e) for (v, n), e in pf.items() if e > 0), reverse=True)
    cycles = {cpu: collections.Counter() for _, cpu, _ in CLOCKS}
    covered = collections.Counter()
    done = 0.0
    for k, (ins, v, n, e) in enumerate(hot):
        if done >= COVER * total or k >= MAX_BLOCKS:
            break
        stage = prog.where(v)[2]
        res = {cpu: mca_cycles(prog, v, n, cpu) for cpu in set(c for _, c, _ in CLOCKS)}
        if any(c is None for c in res.values()):
            continue
        for cpu, c in res.items():
            cycles[cpu][stage] += c * e
        covered[stage] += ins
        done += ins
    est = {}
    for cpu in cycles:
        all_ipc = sum(covered.values()) / max(sum(cycles[cpu].values()), 1e-9)
        est[cpu] = {}
        for stage, ins in stage_insns.items():
            c = cycles[cpu][stage]
            ipc = covered[stage] / c if covered[stage] > 0 and c > 0 else all_ipc
            est[cpu][stage] = c + max(ins - covered[stage], 0) / ipc
    return {"stages": dict(stage_insns), "total": total, "covered": done / total if total else 0,
            "cycles": est, "top": func_insns.most_common(12)}


def working_set(out, sizes):
    """Distinct 64-byte lines loaded or stored per frame (plugin's mark mode), against 1 MiB."""
    rows = []
    for task, steady in (("video", slice(2, 5)), ("stab", slice(2, 6))):
        for size in sizes:
            path = os.path.join(out, "wset-%s-%s.blocks.frames" % (task, size))
            if not os.path.exists(path):
                continue
            frames = [tuple(int(x) for x in l.split()[1:4]) for l in open(path) if l.startswith("frame")]
            frames = sorted(frames[steady])
            if frames:
                lines, accessed, misses = frames[len(frames) // 2]
                rows.append((task, size, lines * 64, accessed, misses * 64))
    if not rows:
        return
    # where the misses come from: the L2 model's misses per stage over the whole run (set-up
    # included, so only the library's stages are shared out), at the largest size
    miss_by = {}
    for task in TASKS:
        prog = Program(out, "aarch64", TASKS[task][0])
        path = os.path.join(out, "wset-%s-%s.blocks" % (task, sizes[-1]))
        miss_by[task] = collections.Counter()
        if os.path.exists(path):
            for line in open(path):
                f = line.split()
                if len(f) == 4 and int(f[3]):
                    _, func, stage = prog.where(int(f[0], 16))
                    if stage in LIB_STAGES:
                        miss_by[task][(stage, func)] += int(f[3])
    print("\nworking set per frame, aarch64: distinct 64-byte lines loaded or stored between two frames'")
    print("entries (median of the steady frames; stab: with reading the next Y4M frame and writing one),")
    print("against a Pi 4's 1 MiB L2, and the lines a 1 MiB 16-way LRU cache fed every access misses")
    print("(no L1, no prefetch): misses above the touched bytes = data streamed in more than once.")
    print("%-5s %-9s %10s %8s %14s %12s %8s" % ("task", "size", "touched", "/ 1 MiB", "bytes accessed",
                                               "L2 misses", "/ touch"))
    for task, size, touched, accessed, missed in rows:
        print("%-5s %-9s %7.2f MB %8.2f %11.1f MB %9.2f MB %8.2f" % (
            task, size, touched / 1e6, touched / 2.0 ** 20, accessed / 1e6, missed / 1e6, missed / touched))
    for task, by in miss_by.items():
        total = sum(by.values())
        if total:
            print("the library's L2-model misses by function, %s %s (share of the library's):" % (task, sizes[-1]))
            for (stage, func), m in by.most_common(8):
                print("  %-10s %-40s %5.1f %%" % (stage, func, 100.0 * m / total))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--arches", default="aarch64 armv7")
    ap.add_argument("--sizes", default="640x360 1280x720 1920x1080")
    args = ap.parse_args()
    arches, sizes = args.arches.split(), args.sizes.split()
    progs = {}
    for arch in arches:
        for task in TASKS:
            progs[(arch, TASKS[task][0])] = Program(args.out, arch, TASKS[task][0])
    results = {}
    for arch in arches:
        for task in TASKS:
            for size in sizes:
                results["%s %s %s" % (arch, task, size)] = analyse(args.out, arch, task, size, progs)
    json.dump(results, open(os.path.join(args.out, "results.json"), "w"), indent=1)

    print("\nARM instructions per frame, executed (qemu-user TCG plugin; millions), and time estimates")
    print("(llvm-mca on the hot blocks; an ESTIMATE: L1 hits, predicted branches). video = home_video_config,")
    print("one new frame registered against cached features; stab = home-stab per frame (registration on")
    print("luma at 1/2 size above 960 px wide, then the warp of the I420 frame). lib = the library's stages.")
    short = {"homography": "homog", "lib-other": "other"}
    head = "%-7s %-5s %-9s " % ("arch", "task", "size") + " ".join(
        "%7s" % short.get(s, s)[:7] for s in STAGES) + " | %7s %5s %7s %7s %7s %5s" % (
        "lib", "IPC", "A72@1.5", "A72@1.8", "A76@2.4", "mca%")
    print(head)
    print("-" * len(head))
    for key, r in results.items():
        arch, task, size = key.split()
        lib = sum(r["stages"].get(s, 0) for s in LIB_STAGES)
        cyc = {c: sum(r["cycles"][cpu].get(s, 0) for s in LIB_STAGES) for (c, cpu, _) in CLOCKS}
        ms = ["%7.2f" % (cyc[c] / (ghz * 1e6)) for (c, cpu, ghz) in CLOCKS]
        print("%-7s %-5s %-9s " % (arch, task, size) +
              " ".join("%7.2f" % (r["stages"].get(s, 0) / 1e6) for s in STAGES) +
              " | %7.2f %5.2f %s %5.0f" % (lib / 1e6, lib / max(cyc["A72@1.5"], 1), " ".join(ms),
                                          100 * r["covered"]))
    print("ms: the library's stages (lib) on one core; libc = memset/memcpy/libm and, for stab, the")
    print("tool's Y4M reading; tool = the driver and home-stab itself (not counted in lib).")
    for arch in arches:
        for (c, cpu, ghz) in CLOCKS[:2]:
            for size, fps, budget in (("1920x1080", 30, 16.0), ("1280x720", 60, 8.3)):
                r = results.get("%s stab %s" % (arch, size))
                if not r:
                    continue
                ms = sum(r["cycles"][cpu].get(s, 0) for s in LIB_STAGES + ["libc"]) / (ghz * 1e6)
                print("%sp%d registration + warp, one %s core at %s GHz, %s, with libc: %.1f ms: %s %.1f ms "
                      "(half a core)" % (size.split("x")[1], fps, cpu, ghz, arch, ms,
                                         "within" if ms <= budget else "OVER", budget))
    working_set(args.out, sizes)
    print("hottest functions, aarch64 stab at the largest size (M instructions per frame):")
    key = "aarch64 stab %s" % sizes[-1]
    if key in results:
        for (stage, func), ins in results[key]["top"]:
            print("  %-10s %-40s %6.2f" % (stage, func, ins / 1e6))


if __name__ == "__main__":
    sys.exit(main())
