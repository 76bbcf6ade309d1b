#!/usr/bin/env python3
"""home-stab against ffmpeg's stabilisers on synthetic shaky clips with ground truth, in one run.

Clips: photographs from Debian's opencv-doc package (not the desktop wallpaper/background
packages), scaled to cover 800x450 and converted to grey by ffmpeg, then filmed by
home-stab-clip through a shaky camera (central 640x360; a pan plus jitter of three random
sinusoids of 0.08..0.3 cycles/frame and white noise; noise sigma 2). Categories:
  structured   building facades (building.jpg, leuvenA.jpg)
  textured     texture-rich scenes (baboon.jpg, fruits.jpg)
  textureless  the structured photographs with texture decay I' = I + 0.9 (128 - I)
Methods (each run as a whole process, timed by wall clock):
  home-stab          causal (lookahead 0) and with 15 frames of lookahead
  vidstab            ffmpeg vidstabdetect then vidstabtransform (two passes, Gaussian path
                     smoothing, smoothing=15 frames each side, crop=black, optzoom=1)
  deshake            ffmpeg deshake (one pass, translation + rotation, edge=blank)
Metrics, all on luma, computed the same way for every method from its output frames:
  the output-to-input map M_t of each frame is found by aligning the output frame to the input
  frame t (Gauss-Newton similarity fit, coarse to fine); the output camera is then
  O_t = M_t^-1 G_t with G_t the true camera, and
  jitter     px RMS (output pixels: a zoom magnifies it) of the high-frequency part of O_t (tx,
             ty, rotation x half diagonal): what a
             centred Gaussian of sigma 4 frames leaves, 6 frames trimmed at each end
  ITF        mean over consecutive output frames of 10 log10(255^2 / MSE) over the pixels valid
             (inside the input) in both
  stability  Liu et al. 2013: share of the 2nd..6th lowest frequencies in the energy of the
             output path's per-frame translation and rotation, the smaller of the two
  crop       mean scale of M_t (1 = the full frame is shown); valid = mean share of output
             pixels inside the input (below 1: borders)
  follow     px RMS between the low-frequency output path and the intended camera path (the
             clip without jitter) at the output's zoom: the wanted motion that was dropped or
             distorted. ITF rewards dropping it (a frozen picture scores best), so read the two
             together
  fps        frames / wall time of the whole process (both passes for vidstab), and frames per
             CPU second (user + system time of the process and all its threads: steadier on a
             shared machine, and fair to multi-threaded filters)
  ITF ends   the same ITF over the first and last 10 pairs only, and over the pairs between
             (where a two-pass method, which sees the whole clip, can slow the output down)
Usage: python3 bench/stab/compare.py [--quick | --smoke] [--build build] [--frames N] [--out DIR]
         [--size WxH]   (frame size, default 640x360: the scene 1.25x as large, shake and pan
                         scaled with the width)
         [--methods home-stab,home-stab la15,vidstab,deshake] [--stab-args "--theta-bins 64"]
         [--repeat N]   (fps columns from the fastest of N runs per method and clip: on a shared
                         machine single runs vary by 10-50 %)
"""
import argparse
import glob
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
W, H = 640, 360
SCENE_W, SCENE_H = 800, 450
HALF_DIAG = 0.5 * np.hypot(W, H)
ALIGN_LEVELS = 3   # pyramid levels of the metric's alignment: the coarsest about 160 px wide
PHOTOS = {
    "structured": [("building.jpg", 0.0), ("leuvenA.jpg", 0.0)],
    "textured": [("baboon.jpg", 0.0), ("fruits.jpg", 0.0)],
    "textureless": [("building.jpg", 0.9), ("leuvenA.jpg", 0.9)],
}


def run(cmd, **kw):
    """Run cmd; returns (wall seconds, CPU seconds of the process and its threads)."""
    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kw)
    wall = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(map(str, cmd)), r.stderr.decode(errors="replace")[-2000:]))
    return wall, (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)


def photo_dir(cache):
    """opencv-doc's example images: the eval cache, or apt-get download + dpkg -x."""
    found = glob.glob(str(cache / "opencv-doc/usr/share/doc/opencv-doc/examples/data"))
    if found:
        return Path(found[0])
    cache.mkdir(parents=True, exist_ok=True)
    debs = sorted(cache.glob("opencv-doc_*.deb"))
    if not debs:
        run(["apt-get", "download", "opencv-doc"], cwd=cache)
        debs = sorted(cache.glob("opencv-doc_*.deb"))
    run(["dpkg", "-x", str(debs[-1]), str(cache / "opencv-doc")])
    return cache / "opencv-doc/usr/share/doc/opencv-doc/examples/data"


def read_y4m_luma(path):
    d = open(path, "rb").read()
    nl = d.index(b"\n")
    tags = {t[:1]: t[1:] for t in d[:nl].split()[1:]}
    w, h = int(tags[b"W"]), int(tags[b"H"])
    c = (tags.get(b"C") or b"420").decode()
    frame = w * h * (2 if c.startswith("422") else 1 if c == "mono" else 1.5)
    frames, pos = [], nl + 1
    while pos < len(d):
        pos = d.index(b"\n", pos) + 1
        frames.append(np.frombuffer(d, np.uint8, w * h, pos).reshape(h, w))
        pos += int(frame)
    return frames


def read_truth(path, intended=False):
    """The true camera per frame (reference -> frame t), or the intended one (no jitter)."""
    rows = np.loadtxt(path, delimiter=",", skiprows=1)
    c = 7 if intended else 1
    g = np.zeros((len(rows), 3, 3))
    g[:, 0, :] = rows[:, c:c + 3]
    g[:, 1, :] = rows[:, c + 3:c + 6]
    g[:, 2, 2] = 1
    return g


# ---- similarity alignment: find M with out(q) ~ in(M q) -------------------------------------

def bilinear(img, x, y):
    h, w = img.shape
    x = np.clip(x, 0, w - 1.001)
    y = np.clip(y, 0, h - 1.001)
    x0 = x.astype(np.int32)
    y0 = y.astype(np.int32)
    fx = x - x0
    fy = y - y0
    a = img[y0, x0] * (1 - fx) + img[y0, x0 + 1] * fx
    b = img[y0 + 1, x0] * (1 - fx) + img[y0 + 1, x0 + 1] * fx
    return a * (1 - fy) + b * fy


def pyramid(img, levels):
    out = [img.astype(np.float32)]
    for _ in range(levels - 1):
        p = out[-1]
        p = p[: p.shape[0] // 2 * 2, : p.shape[1] // 2 * 2]
        out.append(0.25 * (p[0::2, 0::2] + p[1::2, 0::2] + p[0::2, 1::2] + p[1::2, 1::2]))
    return out


def sim_matrix(p, cx, cy):
    a, b, tx, ty = p
    return np.array([[a, -b, cx + tx - a * cx + b * cy], [b, a, cy + ty - b * cx - a * cy], [0, 0, 1.0]])


def align(out_img, in_pyr, p0, iters=12):
    """Gauss-Newton on (a, b, tx, ty) about the centre, coarse to fine; returns p, M, rms."""
    levels = len(in_pyr)
    out_pyr = pyramid(out_img, levels)
    p = np.array(p0, float)
    rms = 0.0
    for lev in range(levels - 1, -1, -1):
        s = 2.0 ** lev
        o, i = out_pyr[lev], in_pyr[lev]
        h, w = o.shape
        gy, gx = np.gradient(i)
        step = 2 if lev == 0 else 1
        ys, xs = np.mgrid[2:h - 2:step, 2:w - 2:step].astype(np.float64)
        cx, cy = 0.5 * (W - 1), 0.5 * (H - 1)
        # level coordinates: full = s * lev + (s - 1) / 2
        qx = s * xs + 0.5 * (s - 1) - cx
        qy = s * ys + 0.5 * (s - 1) - cy
        ov = o[ys.astype(int), xs.astype(int)].astype(np.float64)
        for _ in range(iters):
            a, b, tx, ty = p
            ux = a * qx - b * qy + tx + cx
            uy = b * qx + a * qy + ty + cy
            lx = (ux - 0.5 * (s - 1)) / s
            ly = (uy - 0.5 * (s - 1)) / s
            valid = (lx > 1) & (lx < i.shape[1] - 2) & (ly > 1) & (ly < i.shape[0] - 2) & (ov > 2)
            if valid.sum() < 200:
                break
            iv = bilinear(i, lx[valid], ly[valid])
            ix = bilinear(gx, lx[valid], ly[valid]) / s
            iy = bilinear(gy, lx[valid], ly[valid]) / s
            X, Y = qx[valid], qy[valid]
            J = np.stack([ix * X + iy * Y, -ix * Y + iy * X, ix, iy], 1)
            r = ov[valid] - iv
            rms = float(np.sqrt(np.mean(r * r)))
            dp = np.linalg.lstsq(J, r, rcond=None)[0]
            p += dp
            if abs(dp[2]) + abs(dp[3]) < 1e-3 * s and abs(dp[0]) + abs(dp[1]) < 1e-6:
                break
    return p, sim_matrix(p, 0.5 * (W - 1), 0.5 * (H - 1)), rms


def output_maps(outs, ins):
    """M_t for every output frame; the first frame tries a few zooms, later ones start from the
    previous estimate."""
    maps = []
    p_prev = None
    for t, (o, i) in enumerate(zip(outs, ins)):
        in_pyr = pyramid(i, ALIGN_LEVELS)
        if p_prev is None:
            best = None
            for z in (1.0, 0.9, 0.8, 0.7):
                cand = align(o, in_pyr, (z, 0, 0, 0))
                if best is None or cand[2] < best[2]:
                    best = cand
            p, m, _ = best
        else:
            p, m, _ = align(o, in_pyr, p_prev)
        maps.append(m)
        p_prev = p
    return np.array(maps)


# ---- metrics ---------------------------------------------------------------------------------

def components(g):
    cx, cy = 0.5 * (W - 1), 0.5 * (H - 1)
    tx = g[:, 0, 0] * cx + g[:, 0, 1] * cy + g[:, 0, 2] - cx
    ty = g[:, 1, 0] * cx + g[:, 1, 1] * cy + g[:, 1, 2] - cy
    rot = np.arctan2(g[:, 1, 0], g[:, 0, 0])
    return np.stack([tx, ty, rot * HALF_DIAG], 1)


def lowpass(path, sigma=4.0):
    n = len(path)
    k = np.arange(-int(3 * sigma), int(3 * sigma) + 1)
    wts = np.exp(-0.5 * (k / sigma) ** 2)
    smooth = np.zeros_like(path)
    for t in range(n):
        idx = np.clip(t + k, 0, n - 1)
        smooth[t] = (wts[:, None] * path[idx]).sum(0) / wts.sum()
    return smooth


def jitter(path, sigma=4.0, trim=6):
    n = len(path)
    hf = (path - lowpass(path, sigma))[trim:n - trim]
    return float(np.sqrt(np.mean(hf ** 2)))


def follow(path, intended, scale, trim=6):
    """RMS px between the output's low-frequency path and the intended camera seen at the
    output's zoom (offset removed): how much of the wanted motion was kept, or added."""
    want = intended.copy()
    want[:, :2] /= scale
    d = (lowpass(path) - want)[trim:len(path) - trim]
    d -= d.mean(0)
    return float(np.sqrt(np.mean(d ** 2)))


def stability(path):
    def share(v):
        e = np.abs(np.fft.fft(v)) ** 2
        e = e[1:len(v) // 2 + 1]
        return float(e[:5].sum() / max(e.sum(), 1e-12))
    d = np.diff(path, axis=0)
    return min(0.5 * (share(d[:, 0]) + share(d[:, 1])), share(d[:, 2]))


def valid_mask(m):
    ys, xs = np.mgrid[0:H, 0:W].astype(np.float64)
    u = m[0, 0] * xs + m[0, 1] * ys + m[0, 2]
    v = m[1, 0] * xs + m[1, 1] * ys + m[1, 2]
    return (u >= 0) & (u <= W - 1) & (v >= 0) & (v <= H - 1)


def itf(outs, maps, ends=10):
    vals = []
    masks = [valid_mask(m) for m in maps]
    for t in range(len(outs) - 1):
        common = masks[t] & masks[t + 1]
        if common.sum() < 1000:
            continue
        d = outs[t][common].astype(np.float64) - outs[t + 1][common]
        vals.append(10 * np.log10(255.0 ** 2 / max(np.mean(d * d), 1e-6)))
    mid = vals[ends:len(vals) - ends] if len(vals) > 2 * ends else vals
    end = vals[:ends] + vals[len(vals) - ends:] if len(vals) > 2 * ends else vals
    return float(np.mean(vals)), float(np.mean([m.mean() for m in masks])), float(np.mean(end)), float(np.mean(mid))


def measure(outs, ins, truth, intended):
    maps = output_maps(outs, ins)
    o = np.array([np.linalg.inv(m) @ g for m, g in zip(maps, truth)])
    path = components(o)
    it, valid, it_ends, it_mid = itf(outs, maps)
    crop = float(np.mean(np.sqrt(np.abs(np.linalg.det(maps[:, :2, :2])))))
    return {"jitter": jitter(path), "itf": it, "itf_ends": it_ends, "itf_mid": it_mid, "stability": stability(path), "crop": min(crop, 1.0), "valid": valid,
            "follow": follow(path, components(intended), crop)}


# ---- the run ---------------------------------------------------------------------------------

def set_size(text):
    """Frame and scene size for the run (module globals: the metrics use them)."""
    global W, H, SCENE_W, SCENE_H, HALF_DIAG, ALIGN_LEVELS
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        sys.exit("--size: expected WxH, got %r" % text)
    if w < 320 or h < 180 or w % 2 or h % 2:
        sys.exit("--size: even and at least 320x180, got %r" % text)
    W, H = w, h
    SCENE_W, SCENE_H = (w * 5 // 4 + 1) // 2 * 2, (h * 5 // 4 + 1) // 2 * 2
    HALF_DIAG = 0.5 * np.hypot(W, H)
    # a frame's change of M_t at 1080p is 3x that at 640x360: without the extra levels the fit
    # started from the previous frame's map fell into a wrong minimum on fine texture
    ALIGN_LEVELS = 1 + int(round(np.log2(W / 160.0)))


def method_commands(stab, extra):
    """Method name -> f(input, output) giving the commands to run, in order (extra: more
    home-stab options)."""
    return {
        # causal: home-stab's own default lookahead is 30 frames (a file has no latency limit)
        "home-stab": lambda c, o: [[str(stab), "--quiet", "--lookahead", "0"] + extra + [c, o]],
        "home-stab la15": lambda c, o: [[str(stab), "--quiet", "--lookahead", "15"] + extra + [c, o]],
        "vidstab": lambda c, o: [
            ["ffmpeg", "-v", "error", "-y", "-i", c, "-vf", "vidstabdetect=result=%s.trf" % o, "-f", "null", "-"],
            ["ffmpeg", "-v", "error", "-y", "-i", c, "-vf", "vidstabtransform=input=%s.trf:crop=black:optzoom=1:smoothing=15" % o,
             "-pix_fmt", "yuv420p", "-f", "yuv4mpegpipe", o]],
        "deshake": lambda c, o: [["ffmpeg", "-v", "error", "-y", "-i", c, "-vf", "deshake=edge=blank", "-pix_fmt", "yuv420p",
                                  "-f", "yuv4mpegpipe", o]],
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--frames", type=int, default=120)
    ap.add_argument("--quick", action="store_true", help="one photograph per category, 60 frames")
    ap.add_argument("--smoke", action="store_true", help="CI: one structured clip of 40 frames")
    ap.add_argument("--out", default=None, help="work directory (default BUILD/bench-stab)")
    ap.add_argument("--cache", default=os.environ.get("HOME_EVAL_CACHE", str(REPO / "build/eval-cache")))
    ap.add_argument("--methods", default="home-stab,home-stab la15,vidstab,deshake",
                    help="comma-separated subset of the methods to run")
    ap.add_argument("--stab-args", default="", help="extra home-stab options (e.g. --theta-bins 64)")
    ap.add_argument("--repeat", type=int, default=1, help="run each method N times, fps from the fastest")
    ap.add_argument("--size", default="%dx%d" % (W, H), help="frame size WxH (even, at least 320x180)")
    args = ap.parse_args()
    set_size(args.size)
    build = REPO / args.build
    work = Path(args.out) if args.out else build / "bench-stab"
    work.mkdir(parents=True, exist_ok=True)
    frames = 40 if args.smoke else 60 if args.quick else args.frames
    photos = photo_dir(Path(args.cache))
    stab, clip = build / "bin/home-stab", build / "bin/home-stab-clip"
    for tool in (stab, clip):
        if not tool.exists():
            sys.exit("%s missing: run make BUILD=%s first" % (tool, args.build))

    methods = method_commands(stab, args.stab_args.split())
    chosen = [m.strip() for m in args.methods.split(",")]
    for m in chosen:
        if m not in methods:
            sys.exit("unknown method %r (known: %s)" % (m, ", ".join(methods)))
    methods = {k: v for k, v in methods.items() if k in chosen}
    results = {}   # (category, method) -> list of metric dicts
    input_jitter = {}
    for cat, items in PHOTOS.items():
        if args.smoke and cat != "structured":
            continue
        for k, (name, decay) in enumerate(items[:1] if args.quick or args.smoke else items):
            stem = "%s_%s" % (cat, Path(name).stem)
            pgm = work / ("%s_%dx%d.pgm" % (Path(name).stem, SCENE_W, SCENE_H))
            if not pgm.exists():
                run(["ffmpeg", "-v", "error", "-y", "-i", str(photos / name), "-vf",
                     "scale=%d:%d:force_original_aspect_ratio=increase,crop=%d:%d,format=gray" % (SCENE_W, SCENE_H, SCENE_W, SCENE_H),
                     str(pgm)])
            c, truth_csv = work / (stem + ".y4m"), work / (stem + "_truth.csv")
            run([str(clip), "--scene", str(pgm), "--frames", str(frames), "--width", str(W), "--height", str(H),
                 "--shake", "%g" % (4 * W / 640), "--rot", "0.3", "--pan", "%g" % (60 * W / 640),
                 "--decay", str(decay), "--noise", "2", "--seed", str(11 + k), str(c), str(truth_csv)])
            ins = read_y4m_luma(c)
            truth = read_truth(truth_csv)
            intended = read_truth(truth_csv, intended=True)
            input_jitter.setdefault(cat, []).append(jitter(components(truth)))
            for mname, cmds in methods.items():
                o = work / ("%s_%s.y4m" % (stem, mname.replace(" ", "_")))
                wall = cpu = float("inf")
                for _ in range(max(args.repeat, 1)):
                    times = [run(cmd) for cmd in cmds(str(c), str(o))]
                    wall = min(wall, sum(t[0] for t in times))
                    cpu = min(cpu, sum(t[1] for t in times))
                outs = read_y4m_luma(o)
                if len(outs) != len(ins):
                    sys.exit("%s wrote %d frames of %d" % (mname, len(outs), len(ins)))
                m = measure(outs, ins, truth, intended)
                m["fps"] = len(ins) / wall
                m["cpu_fps"] = len(ins) / cpu
                results.setdefault((cat, mname), []).append(m)
                print("%-12s %-22s %-15s jitter %6.3f px  ITF %6.2f dB (ends %6.2f, between %6.2f)  stability %.3f  crop %.3f  valid %.3f  follow %5.2f px  %6.1f fps (%.1f per CPU s)" %
                      (cat, Path(name).stem + (" a=%.1f" % decay if decay else ""), mname, m["jitter"], m["itf"], m["itf_ends"], m["itf_mid"],
                       m["stability"], m["crop"], m["valid"], m["follow"], m["fps"], m["cpu_fps"]), flush=True)

    print("\n%d frames of %dx%d per clip; input jitter (px RMS):" % (frames, W, H),
          ", ".join("%s %.2f" % (c, np.mean(v)) for c, v in input_jitter.items()))
    print("\n| category | method | jitter px | ITF dB | ITF ends / between | stability | crop | valid | follow px | fps (wall) | frames per CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for (cat, mname), ms in results.items():
        avg = {k: np.mean([m[k] for m in ms]) for k in ms[0]}
        print("| %s | %s | %.3f | %.2f | %.2f / %.2f | %.3f | %.3f | %.3f | %.2f | %.1f | %.1f |" %
              (cat, mname, avg["jitter"], avg["itf"], avg["itf_ends"], avg["itf_mid"], avg["stability"], avg["crop"], avg["valid"], avg["follow"], avg["fps"],
               avg["cpu_fps"]))


if __name__ == "__main__":
    main()
