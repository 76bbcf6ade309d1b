#!/usr/bin/env python3
"""home-stab against ffmpeg's stabilisers on a real-world set: clips with the events real
footage has (moving objects, occluders, cuts, fades, exposure changes, codecs, zoom and pans)
and real camera sequences, per clip, in one run (GitHub issue 18, item 8).

Rendered clips: a photograph or a scenes.py scene covering 960x540, filmed at 640x360 by a
camera whose shake is home-stab-clip's (compare.py's shake: 4 px and 0.3 deg RMS of three
sinusoids and white noise; read from its truth CSV) on top of an intended path, then the
scenario's event, sensor noise sigma 2 and 8 bits. The truth (truth.json beside each clip)
holds each frame's camera (reference -> frame, as home-stab-clip's CSV), the intended camera,
the cut frames (first frame of each new shot) and the blank frames (too dark to measure).
Scenarios (each in the tuning and the test half, with other scenes and seeds):
  static     static camera, textured objects moving over 10-30 % of the frame, H.264
             (trust_data.build_static: the trust evaluation's static clips, 300 frames)
  occluder   one shaky clip as it is and with a large occluder for 30 frames (tuning: a
             textured object passing, and a dark blurred hand at the lens; test: the hand)
  cuts       three shaky shots of different scenes joined by hard cuts
  fade       a fade to black and back, then a 10-frame dissolve, between three shots
  exposure   gain steps of +-1 EV every 30 frames; a slow auto-exposure ramp (-1 to +1 EV)
  codec      libx264 at 1.5 Mbit/s; libx265 at 1 Mbit/s (30 fps), decoded back to Y4M
  zoom, pan  an intended slow zoom in to 1.25x and out again; a 200 px pan with a 80 px tilt;
             a still camera that moves 63 px hand-held (frames 30-75, at full speed within 2
             frames) and stands still again (still_move)
  scene      the earlier rendered cases: few long edges, horizon in fog, structured,
             textured, low light (scenes.low_light instead of the noise)
Real footage (no truth), visp-images-data's camera sequences at their native size (cropped to
even): mire-2 (first 300 of its 502 frames), mbt/cube, cube, cube.mpeg (MPEG-1 of cube),
mbt-depth/castel/castel, ellipse-1, line.
Methods: compare.method_commands (home-stab causal and --lookahead 15, vidstab two-pass,
deshake), each run as a whole process; frames per CPU second as in compare.py.
Metrics (luma):
  jitter, ITF, follow, crop  compare.measure's (output frames aligned to their input frames,
             compared with the truth), per shot: cuts and blank frames split a clip into shots,
             each measured on its own and the results pooled (RMS, mean)
  drift      static clips: the largest distance of the low-passed output path (sigma 4
             frames) from its first frame, px
  zoom err   zoom clips: RMS of the low-passed output scale against the intended, % (mean
             offset removed: the crop zoom is not an error)
  pc jitter  without truth, the same for every clip: phase correlation (numpy FFT, Hann window,
             subpixel parabola peak) between consecutive frames' central 70 %; their shifts
             summed to a path per shot; RMS of what a sigma 4 Gaussian leaves (compare.jitter)
  ITF c70    mean PSNR of consecutive frames over their central 70 %
  registration  (every clip with a truth) home-stab's own per-frame registrations, from its
             --csv raw path at --lookahead 15, against the true camera motion: failures, and
             of the frames reported ok or still the mean corner error and the share more than
             2 px off (silent errors); --registration-only measures only this
Sets: --set tuning | test | all (thresholds of the library are tuned on tuning only).
Usage: python3 bench/stab/realworld.py [--set all] [--quick] [--clips NAME,...] [--jobs 2]
         [--build build] [--cache DIR] [--stab-args "..."] [--methods ...] [--out DIR]
         [--registration-only] [--speed N]
Rendered clips are cached in OUT/clips (default build/bench-stab-realworld); the report goes to
stdout and OUT/results.md, the numbers to OUT/results.json.
"""
import argparse
import concurrent.futures
import dataclasses
import json
import os
import re
import subprocess
import sys
import tarfile
import time
import types

from pathlib import Path

import csv
import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
sys.path.insert(0, str(REPO / "bench/eval"))
import compare as C                                  # noqa: E402  (metrics, methods, I/O)

W, H = 640, 360
SCENE_SCALE = 1.5          # the scene covers 1.5x the frame: room for pans, zoom and shake
GEN = 1                    # bump when the rendering changes: cached clips are then redone
NOISE = 2.0
TRIM = 6                   # compare.jitter's trim at each end of a shot
MIN_SHOT = 20              # shorter shots are not measured
VISP_DIR = "usr/share/visp-images-data/ViSP-images"
METHODS = ["home-stab", "home-stab la15", "vidstab", "deshake"]


# ---- clips ---------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Clip:
    name: str
    half: str              # "tuning" or "test"
    scenario: str
    why: str
    source: str
    build: object          # build(ctx, frames) -> (list of uint8 frames or y4m path, truth)
    frames: int = 120
    quick: bool = False    # part of --quick


def item(scene=None, photo=None, condition=None):
    """A trust_catalogue.Item (a photograph or a scenes.py scene) to film."""
    import trust_catalogue
    return trust_catalogue.Item("", photo=photo, scene=scene, condition=condition)


def photo(source, file):
    from data import Photo
    return Photo(source, file, "")


def bench_shake(ctx, frames, seed):
    """home-stab-clip's camera for a seed: (jitter per frame as tx, ty, angle rad; its intended
    path as tx, ty, angle rad). Its intended path is compare.py's: a 60 px pan, drift, tilt."""
    csv = ctx.work / "shake" / ("seed%d_n%d.csv" % (seed, frames))
    if not csv.exists():
        csv.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run([str(ctx.clip_tool), "--frames", str(frames), "--shake", "4", "--rot", "0.3",
                        "--pan", "60", "--noise", "0", "--seed", str(seed), "-", str(csv)],
                       stdout=subprocess.DEVNULL, check=True)
    g, i = C.read_truth(csv), C.read_truth(csv, intended=True)
    to_rad = np.array([1.0, 1.0, 1.0 / C.HALF_DIAG])
    return (C.components(g) - C.components(i)) * to_rad, C.components(i) * to_rad


def camera(tx, ty, angle, scale=1.0):
    """Similarity about the frame centre (home-stab-clip's, with a scale)."""
    cx, cy = 0.5 * (W - 1), 0.5 * (H - 1)
    c, s = scale * np.cos(angle), scale * np.sin(angle)
    return np.array([[c, -s, cx + tx - c * cx + s * cy], [s, c, cy + ty - s * cx - c * cy],
                     [0.0, 0.0, 1.0]])


def ease(u):
    return 0.5 - 0.5 * np.cos(np.pi * np.clip(u, 0, 1))


def motion(ctx, frames, seed, kind="bench"):
    """Cameras (true and intended, 3x3 each) and the intended scale per frame."""
    jit, bench = bench_shake(ctx, frames, seed)
    u = np.arange(frames) / max(frames - 1, 1)
    scale = np.ones(frames)
    if kind == "bench":
        want = bench
    elif kind == "zoom":          # in to 1.25x and out again, no pan
        want = np.zeros((frames, 3))
        scale = 1 + 0.25 * ease(2 * u) - 0.25 * ease(2 * u - 1)
    elif kind == "pan":           # a deliberate pan right-to-left and a tilt, eased
        want = np.stack([100 - 200 * ease(u), -40 + 80 * ease(u), np.zeros(frames)], 1)
    elif kind == "still_move":    # still, a hand-held move that starts within 2 frames, still
        start, stop = frames // 4, frames // 4 + 45
        t = np.arange(frames)
        speed = np.clip(np.minimum((t - start + 1) / 2, (stop - t) / 3), 0, 1)
        walk = np.cumsum(speed) / speed.sum()
        want = np.stack([60 * walk, -20 * walk, np.zeros(frames)], 1)
        jit = jit * ((t >= start) & (t <= stop))[:, None]
    else:
        raise ValueError(kind)
    g = [camera(*(want[t] + jit[t]), scale[t]) for t in range(frames)]
    i = [camera(*want[t], scale[t]) for t in range(frames)]
    return g, i, scale


def scene_image(ctx, what):
    import trust_data
    if what.photo:
        ctx.lib.fetch([what.photo])
    return trust_data.world(ctx.lib, what, int(W * SCENE_SCALE), int(H * SCENE_SCALE))


def film(scene, cams):
    """Noise-free frames (float, 0..255) of the scene seen by each camera: the frame is the
    scene's centre, frame t shows reference point x at cams[t] x (as home-stab-clip)."""
    sh, sw = scene.shape
    ys, xs = np.mgrid[0:H, 0:W].astype(np.float64)
    out = []
    for g in cams:
        inv = np.linalg.inv(g)
        u = inv[0, 0] * xs + inv[0, 1] * ys + inv[0, 2] + 0.5 * (sw - W)
        v = inv[1, 0] * xs + inv[1, 1] * ys + inv[1, 2] + 0.5 * (sh - H)
        out.append(C.bilinear(scene, u, v))
    return out


def truth_of(g, i, cuts=(), blank=(), static=False, scale=None, **info):
    t = {"g": [m[:2].ravel().tolist() for m in g], "intended": [m[:2].ravel().tolist() for m in i],
         "cuts": list(cuts), "blank": sorted(blank), "static": static}
    if scale is not None and np.ptp(scale) > 0:
        t["scale"] = list(map(float, scale))
    t.update(info)
    return t


def noisy(frames, key):
    from common import rng_for
    rng = rng_for("realworld|noise|" + key)
    return [np.clip(np.rint(f + rng.normal(0, NOISE, f.shape)), 0, 255).astype(np.uint8)
            for f in frames]


def shaky(ctx, what, frames, seed, kind="bench"):
    g, i, scale = motion(ctx, frames, seed, kind)
    return film(scene_image(ctx, what), g), g, i, scale


# ---- scenario builders: (ctx, clip) -> (frames or a y4m path, truth) -------------------------

def build_scene(what, seed, low_light=False, kind="bench"):
    def build(ctx, clip):
        frames, g, i, scale = shaky(ctx, what, clip.frames, seed, kind)
        if low_light:
            import scenes
            from common import rng_for
            rng = rng_for("realworld|lowlight|" + clip.name)
            gain = scenes.low_light_params(rng)["gain"]
            return [scenes.low_light(f, gain, rng) for f in frames], truth_of(g, i, gain=gain)
        return noisy(frames, clip.name), truth_of(g, i, scale=scale)
    return build


def build_static(trust_set, index):
    """The trust evaluation's static clip (trust_data.build_static, one clip of its catalogue),
    rendered into this bench's work directory."""
    def build(ctx, clip):
        import trust_catalogue
        import trust_data
        one = types.SimpleNamespace(
            static_clips=lambda which: trust_catalogue.static_clips(which)[index:index + 1],
            STATIC_COVER=trust_catalogue.STATIC_COVER, STATIC_SALT=trust_catalogue.STATIC_SALT,
            STATIC_SHARE=trust_catalogue.STATIC_SHARE, QUICK={"static_clips": 1})
        _, info = trust_data.build_static(ctx.lib, trust_set, False, ctx.work / "trust", one,
                                          clip.frames, jobs=1)
        eye = [np.eye(3)] * clip.frames
        return Path(info[0]["y4m"]), truth_of(eye, eye, static=True,
                                              moving_share_max=info[0]["moving_share_max"])
    return build


def soft_ellipse(cx, cy, rx, ry, edge):
    """Mask of an ellipse with a soft edge about `edge` px wide."""
    ys, xs = np.mgrid[0:H, 0:W].astype(np.float64)
    r = np.sqrt(((xs - cx) / rx) ** 2 + ((ys - cy) / ry) ** 2)
    return 0.5 - 0.5 * np.tanh((r - 1) * min(rx, ry) / edge)


def occluder_layers(ctx, kind, frames, start, length=30):
    """Per frame (mask, picture) of the occluder, or None where there is none."""
    layers = [None] * frames
    if kind == "object":          # a textured object slides in from the right, drifts, leaves
        tex = scene_image(ctx, item(photo=photo("opencv-doc", "graf1.png")))
        cols = np.arange(W)
        for k in range(length):
            shown = min(k / 5, (length - 1 - k) / 5, 1)
            cx = W * (1.35 - 0.7 * shown) - 2.0 * k
            picture = tex[:H, np.clip(cols - int(cx) + tex.shape[1] // 2, 0, tex.shape[1] - 1)]
            layers[start + k] = (soft_ellipse(cx, 0.5 * H, 0.33 * W, 0.42 * H, 1.5), picture)
    else:                          # a dark blurred hand over the lower left, trembling
        for k in range(length):
            t = start + k
            cover = min(k / 4, (length - 1 - k) / 4, 1)
            cx = -0.25 * W + 0.45 * W * cover + 3 * np.sin(0.7 * k)
            cy = 1.2 * H - 0.3 * H * cover + 2 * np.cos(0.5 * k)
            m = soft_ellipse(cx, cy, 0.45 * W, 0.7 * H, 25.0)
            ys = np.mgrid[0:H, 0:W][0]
            layers[t] = (m, 22.0 + 10.0 * ys / H)
    return layers


def build_occluder(what, seed, kind, start=45):
    """The shaky clip with an occluder (kind "object" or "hand"), or without (kind None)."""
    def build(ctx, clip):
        frames, g, i, _ = shaky(ctx, what, clip.frames, seed)
        info = {}
        if kind:
            shares = []
            for t, layer in enumerate(occluder_layers(ctx, kind, clip.frames, start)):
                if layer is not None:
                    m, pic = layer
                    frames[t] = frames[t] * (1 - m) + pic * m
                    shares.append(float(np.mean(m > 0.5)))
            info = {"occluded": [start, start + len(shares)], "occluded_share_max": max(shares)}
        return noisy(frames, clip.name), truth_of(g, i, **info)
    return build


def build_shots(shots, transition):
    """Shots (item, frames, seed) joined by hard cuts ("cut"), or ("fade") the first two by a
    fade to black and back and the last two by a 10-frame dissolve."""
    def build(ctx, clip):
        frames, g, i, cuts, blank = [], [], [], [], set()
        for k, (what, n, seed) in enumerate(shots):
            f, gk, ik, _ = shaky(ctx, what, n, seed)
            if k and transition == "cut":
                cuts.append(len(frames))
            elif k == 1:               # out over 7 frames, 2 black, in over 7
                ramp = [(j + 1) / 8 for j in range(7)]
                for j, gain in enumerate(ramp[::-1]):
                    frames[-7 + j] = frames[-7 + j] * gain
                    if gain < 0.3:     # too dark to measure
                        blank.add(len(frames) - 7 + j)
                for _ in range(2):
                    blank.add(len(frames))
                    frames.append(np.zeros((H, W)))
                    g.append(g[-1])
                    i.append(i[-1])
                cuts.append(len(frames))
                for j, gain in enumerate(ramp):
                    f[j] = f[j] * gain
                    if gain < 0.3:
                        blank.add(len(frames) + j)
            elif k == 2:               # the last 10 frames and the next shot's first 10 mix
                n0 = len(frames) - 10
                for j in range(10):
                    a = (j + 0.5) / 10
                    f[j] = (1 - a) * frames[n0 + j] + a * f[j]
                # the truth follows the shot that dominates: the old one for 5 frames
                frames, g, i = frames[:n0], g[:n0 + 5], i[:n0 + 5]
                gk, ik = gk[5:], ik[5:]
                cuts.append(n0 + 5)
            frames += f
            g += gk
            i += ik
        return noisy(frames, clip.name), truth_of(g, i, cuts=cuts, blank=blank)
    return build


def build_exposure(what, seed, kind):
    """Gain on the linear intensity (gamma 2.2), clipped: "steps" of +-1 EV every 30 frames,
    or a slow "ramp" from -1 to +1 EV."""
    def build(ctx, clip):
        frames, g, i, _ = shaky(ctx, what, clip.frames, seed)
        t = np.arange(clip.frames)
        if kind == "steps":
            ev = np.array([0, 1, 0, -1])[(t // 30) % 4]
        else:
            ev = -1 + 2 * ease(t / (clip.frames - 1))
        frames = [255 * np.clip((f / 255) ** 2.2 * 2.0 ** e, 0, 1) ** (1 / 2.2)
                  for f, e in zip(frames, ev)]
        return noisy(frames, clip.name), truth_of(g, i, ev=list(map(float, ev)))
    return build


def build_codec(what, seed, codec, kbps):
    def build(ctx, clip):
        frames, g, i, _ = shaky(ctx, what, clip.frames, seed)
        y4m = ctx.clip_dir(clip) / "clip.y4m"
        coded = y4m.with_suffix(".mkv")
        enc = {"libx264": ["-c:v", "libx264", "-preset", "medium"],
               "libx265": ["-c:v", "libx265", "-preset", "medium", "-x265-params", "log-level=error"]}
        p = subprocess.Popen(["ffmpeg", "-v", "error", "-y", "-f", "rawvideo", "-pix_fmt", "gray",
                              "-s", "%dx%d" % (W, H), "-r", "30", "-i", "-"] + enc[codec] +
                             ["-b:v", "%dk" % kbps, "-pix_fmt", "yuv420p", str(coded)],
                             stdin=subprocess.PIPE)
        for f in noisy(frames, clip.name):
            p.stdin.write(f.tobytes())
        p.stdin.close()
        if p.wait():
            sys.exit("ffmpeg %s encode failed" % codec)
        subprocess.run(["ffmpeg", "-v", "error", "-y", "-i", str(coded), "-f", "yuv4mpegpipe",
                        "-pix_fmt", "yuv420p", str(y4m)], check=True)
        real_kbps = coded.stat().st_size * 8 / (clip.frames / 30) / 1000
        coded.unlink()
        return y4m, truth_of(g, i, codec=codec, kbps=real_kbps)
    return build


def build_visp(subdir, first=0, count=None):
    """A visp-images-data sequence: its PGMs in name order (or a video file), native size
    cropped to even."""
    def build(ctx, clip):
        deb = ctx.lib._deb("visp-images-data")
        prefix = "./%s/%s" % (VISP_DIR, subdir)
        files = {}
        with subprocess.Popen(["dpkg-deb", "--fsys-tarfile", str(deb)],
                              stdout=subprocess.PIPE) as proc:
            with tarfile.open(fileobj=proc.stdout, mode="r|") as tar:
                for m in tar:
                    if m.isfile() and (m.name == prefix or (
                            m.name.startswith(prefix + "/") and m.name.endswith(".pgm")
                            and "/" not in m.name[len(prefix) + 1:])):
                        files[m.name] = tar.extractfile(m).read()
        if subdir.endswith(".mpeg"):
            video = ctx.clip_dir(clip) / Path(subdir).name
            video.write_bytes(files[prefix])
            y4m = ctx.clip_dir(clip) / "clip.y4m"
            subprocess.run(["ffmpeg", "-v", "error", "-y", "-i", str(video), "-vf",
                            "crop=trunc(iw/2)*2:trunc(ih/2)*2", "-f", "yuv4mpegpipe",
                            "-pix_fmt", "yuv420p", str(y4m)], check=True)
            video.unlink()
            return y4m, None
        names = sorted(files)[first:None if count is None else first + count]
        frames = []
        for n in names:
            img = read_pgm(files[n])
            frames.append(img[: img.shape[0] // 2 * 2, : img.shape[1] // 2 * 2])
        return frames, None
    return build


def read_pgm(data):
    m = re.match(rb"P5\s+(\d+)\s+(\d+)\s+(\d+)\s", data)
    w, h = int(m.group(1)), int(m.group(2))
    return np.frombuffer(data, np.uint8, w * h, m.end()).reshape(h, w)


def catalogue():
    """Every clip of the set: the tuning half first."""
    P = photo
    building, leuven = P("opencv-doc", "building.jpg"), P("opencv-doc", "leuvenA.jpg")
    baboon, gravel = P("opencv-doc", "baboon.jpg"), P("skimage", "gravel.png")
    castle = P("palapeli", "castle-maintenon.jpg")
    station = P("hugin", "800px-C_Marchi-GrandCentral-adj.jpg")
    bee, flowers = P("palapeli", "european-honey-bee.jpg"), P("libjxl", "jxl/flower/flower.png")
    room, camera_man = P("libjxl", "jxl/hdr_room.png"), P("pywt", "camera.npz")
    aero, motorcycle = P("opencv-doc", "aero1.jpg"), P("skimage", "motorcycle_left.png")
    china = P("sklearn", "china.jpg")
    src_deb = {"opencv-doc": "opencv-doc", "skimage": "python3-skimage",
               "palapeli": "palapeli-data", "hugin": "hugin-data", "libjxl": "libjxl-testdata",
               "pywt": "python3-pywt", "sklearn": "python3-sklearn"}

    def src(p):
        return "%s: %s" % (src_deb[p.source], p.file)

    def S(kind, variant, seed):
        return item(scene=(kind, variant, seed))

    clips = []

    def add(name, half, scenario, why, source, build, frames=120, quick=False):
        clips.append(Clip(name, half, scenario, why, source, build, frames, quick))

    for half, bg, why, source in (
            ("tuning", "static_building", "hotel facade", "opencv-doc: building.jpg"),
            ("test", "static_room", "interior", "libjxl-testdata: jxl/hdr_room.png")):
        add(bg, half, "static", why + " (static), textured objects moving over 10-30 %",
            source + " (trust_catalogue.static_clips)", build_static(half, 0), 300,
            quick=half == "tuning")
    for half, what, s, kinds, seed in (("tuning", leuven, src(leuven), ("object", "hand"), 31),
                                       ("test", station, src(station), ("hand",), 41)):
        add("occl_none_%s" % half, half, "occluder", "shaky, no occluder", s,
            build_occluder(item(photo=what), seed, None))
        for kind in kinds:
            add("occl_%s_%s" % (kind, half), half, "occluder",
                "shaky, %s covering 30-50 %% for 30 frames" % (
                    "a textured object (graf1.png) passing" if kind == "object"
                    else "a dark blurred hand"), s, build_occluder(item(photo=what), seed, kind))
    add("cuts_tuning", "tuning", "cuts", "three shots joined by hard cuts (frames 50, 100)",
        "; ".join(map(src, (building, baboon, motorcycle))),
        build_shots([(item(photo=building), 50, 51), (item(photo=baboon), 50, 52),
                     (item(photo=motorcycle), 50, 53)], "cut"), 150, quick=True)
    add("cuts_test", "test", "cuts", "three shots joined by hard cuts (frames 50, 100)",
        "; ".join(map(src, (castle, bee, room))),
        build_shots([(item(photo=castle), 50, 61), (item(photo=bee), 50, 62),
                     (item(photo=room), 50, 63)], "cut"), 150)
    add("fade_tuning", "tuning", "fade", "fade to black and back, then a 10-frame dissolve",
        "; ".join(map(src, (leuven, gravel, aero))),
        build_shots([(item(photo=leuven), 60, 71), (item(photo=gravel), 60, 72),
                     (item(photo=aero), 50, 73)], "fade"), 152)
    add("fade_test", "test", "fade", "fade to black and back, then a 10-frame dissolve",
        "; ".join(map(src, (station, flowers, china))),
        build_shots([(item(photo=station), 60, 81), (item(photo=flowers), 60, 82),
                     (item(photo=china), 50, 83)], "fade"), 152)
    for half, what, seed in (("tuning", building, 91), ("test", castle, 101)):
        add("exposure_steps_%s" % half, half, "exposure", "gain steps of +-1 EV every 30 frames",
            src(what), build_exposure(item(photo=what), seed, "steps"), 150,
            quick=half == "tuning")
        add("exposure_ramp_%s" % half, half, "exposure", "slow exposure ramp, -1 to +1 EV",
            src(what), build_exposure(item(photo=what), seed + 1, "ramp"))
    for half, what, seed in (("tuning", leuven, 111), ("test", room, 121)):
        add("x264_%s" % half, half, "codec", "libx264 1.5 Mbit/s round trip", src(what),
            build_codec(item(photo=what), seed, "libx264", 1500))
        add("x265_%s" % half, half, "codec", "libx265 1 Mbit/s round trip", src(what),
            build_codec(item(photo=what), seed + 1, "libx265", 1000))
    for half, what, seed in (("tuning", aero, 131), ("test", station, 141)):
        add("zoom_%s" % half, half, "zoom", "intended zoom in to 1.25x and out, plus shake",
            src(what), build_scene(item(photo=what), seed, kind="zoom"), 150)
        add("pan_%s" % half, half, "pan", "intended 200 px pan and 80 px tilt, plus shake",
            src(what), build_scene(item(photo=what), seed + 1, kind="pan"), 150)
    for half, what, seed in (("tuning", motorcycle, 171), ("test", flowers, 181)):
        add("still_move_%s" % half, half, "pan", "still, a 63 px hand-held move that starts "
            "within 2 frames (frames 30-75), still again", src(what),
            build_scene(item(photo=what), seed, kind="still_move"))
    for half, v, scenes in (
            ("tuning", "A", [("flat_art", S("few_edges", "A", "rw0"), 151, False),
                             ("fog_horizon", S("fog_horizon", "A", "rw0"), 152, False),
                             ("structured", item(photo=building), 153, False),
                             ("textured", item(photo=baboon), 154, False),
                             ("low_light", item(photo=leuven), 155, True)]),
            ("test", "B", [("flat_art", S("few_edges", "B", "rw0"), 161, False),
                           ("fog_horizon", S("fog_horizon", "B", "rw0"), 162, False),
                           ("structured", item(photo=castle), 163, False),
                           ("textured", item(photo=bee), 164, False),
                           ("low_light", item(photo=room), 165, True)])):
        for name, what, seed, dim in scenes:
            source = src(what.photo) if what.photo else \
                "scenes.py %s, generator %s, seed rw0" % (what.scene[0], v)
            add("%s_%s" % (name, half), half, "scene", name.replace("_", " "), source,
                build_scene(what, seed, low_light=dim))
    visp = "visp-images-data: ViSP-images/"
    for half, name, sub, why, first, count, quick in (
            ("tuning", "mire2", "mire-2", "camera on a robot over a target of dots", 0, 300,
             False),
            ("tuning", "castel", "mbt-depth/castel/castel", "castle model, moving camera", 0,
             None, False),
            ("tuning", "ellipse1", "ellipse-1", "ellipse drawn on paper, moving camera", 0,
             None, True),
            ("test", "mbt_cube", "mbt/cube", "cube and cylinder on a table, hand-held", 0, None,
             False),
            ("test", "cube", "cube", "cube on a table, moving camera", 0, None, False),
            ("test", "cube_mpeg", "video/cube.mpeg", "the cube sequence as MPEG-1 video", 0,
             None, False),
            ("test", "line", "line", "a dark band on white paper, moving camera: two long edges "
             "on flat areas", 0, None, False)):
        add("real_" + name, half, "real", why, visp + sub, build_visp(sub, first, count), 0,
            quick)
    return clips


# ---- running and measuring -----------------------------------------------------------------

class Context:
    def __init__(self, work, cache, build):
        import trust_data
        self.work = work
        self.lib = trust_data.TrustLibrary(cache)
        self.clip_tool = build / "bin/home-stab-clip"

    def clip_dir(self, clip):
        d = self.work / "clips" / ("%s_n%d" % (clip.name, clip.frames))
        d.mkdir(parents=True, exist_ok=True)
        return d

    def render(self, clip):
        """The clip's Y4M and truth (None for real footage), rendered unless cached."""
        d = self.clip_dir(clip)
        y4m, meta = d / "clip.y4m", d / "truth.json"
        if meta.exists() and y4m.exists():
            saved = json.loads(meta.read_text())
            if saved.get("gen") == GEN:
                return y4m, saved["truth"]
        frames, truth = clip.build(self, clip)
        if isinstance(frames, Path):
            if frames != y4m:
                y4m.write_bytes(frames.read_bytes())
        else:
            import trust_data
            trust_data.write_y4m(y4m, frames)
        meta.write_text(json.dumps({"gen": GEN, "truth": truth}))
        return y4m, truth


def shots(n, truth):
    """[(first, end)] of the clip's shots: split at cuts and blank frames, short ones dropped."""
    if not truth:
        return [(0, n)]
    blank, cuts = set(truth["blank"]), set(truth["cuts"])
    out, first = [], 0
    for t in range(n + 1):
        if t == n or t in blank or t in cuts:
            if t - first >= MIN_SHOT:
                out.append((first, t))
            first = t + 1 if t in blank else t
    return out


def phase_shift(a, b, window):
    """Subpixel translation of b against a by phase correlation (numpy FFT)."""
    fa, fb = np.fft.rfft2(a * window), np.fft.rfft2(b * window)
    r = fb * np.conj(fa)
    corr = np.fft.irfft2(r / (np.abs(r) + 1e-9), a.shape)
    py, px = np.unravel_index(np.argmax(corr), corr.shape)

    def sub(c_m, c_0, c_p):      # parabola through the peak and its neighbours
        d = c_m - 2 * c_0 + c_p
        return 0.5 * (c_m - c_p) / d if d < 0 else 0.0
    h, w = corr.shape
    dy = py + sub(corr[py - 1, px], corr[py, px], corr[(py + 1) % h, px])
    dx = px + sub(corr[py, px - 1], corr[py, px], corr[py, (px + 1) % w])
    return np.array([(dx + w / 2) % w - w / 2, (dy + h / 2) % h - h / 2])


def central(frame):
    h, w = frame.shape
    y0, x0 = int(round(0.15 * h)), int(round(0.15 * w))
    return frame[y0:h - y0, x0:w - x0].astype(np.float64)


def image_metrics(frames, spans):
    """Jitter from phase correlation and ITF over the central 70 %, pooled over shots."""
    c = [central(f) for f in frames]
    window = np.outer(np.hanning(c[0].shape[0]), np.hanning(c[0].shape[1]))
    hf, psnr = [], []
    for a, b in spans:
        steps = [phase_shift(c[t - 1], c[t], window) for t in range(a + 1, b)]
        path = np.vstack([np.zeros(2), np.cumsum(steps, 0)])
        hf.append((C.jitter(path) ** 2, b - a - 2 * TRIM))
        for t in range(a + 1, b):
            d = c[t] - c[t - 1]
            psnr.append(10 * np.log10(255.0 ** 2 / max(np.mean(d * d), 1e-6)))
    return {"pc_jitter": pooled(hf), "itf_c70": float(np.mean(psnr))}


def pooled(pairs):
    """RMS of per-shot RMS values, weighted by their sample counts."""
    w = sum(n for _, n in pairs)
    return float(np.sqrt(sum(v * n for v, n in pairs) / w)) if w else float("nan")


def truth_metrics(outs, ins, truth, spans):
    g = np.array([np.vstack([np.reshape(r, (2, 3)), [0, 0, 1]]) for r in truth["g"]])
    want = np.array([np.vstack([np.reshape(r, (2, 3)), [0, 0, 1]]) for r in truth["intended"]])
    jit, fol, itfs, crops, drift, zoom = [], [], [], [], 0.0, []
    for a, b in spans:
        maps = C.output_maps(outs[a:b], ins[a:b])
        o = np.array([np.linalg.inv(m) @ gt for m, gt in zip(maps, g[a:b])])
        path = C.components(o)
        crop = min(float(np.mean(np.sqrt(np.abs(np.linalg.det(maps[:, :2, :2]))))), 1.0)
        n = b - a - 2 * TRIM
        jit.append((C.jitter(path) ** 2, n))
        fol.append((C.follow(path, C.components(want[a:b]), crop) ** 2, n))
        itfs.append((C.itf(outs[a:b], maps)[0], b - a - 1))
        crops.append((crop, b - a))
        if truth["static"]:
            low = C.lowpass(path)[:, :2]
            drift = max(drift, float(np.max(np.hypot(*(low - low[0]).T))))
        if "scale" in truth:
            scale = np.sqrt(np.abs(np.linalg.det(o[:, :2, :2])))
            err = np.log(C.lowpass(scale[:, None])[:, 0]) - np.log(truth["scale"][a:b])
            err = err[TRIM:len(err) - TRIM]
            zoom.append((float(np.mean((err - err.mean()) ** 2)) * 1e4, n))
    out = {"jitter": pooled(jit), "follow": pooled(fol), "drift": drift,
           "itf": sum(v * n for v, n in itfs) / sum(n for _, n in itfs),
           "crop": sum(v * n for v, n in crops) / sum(n for _, n in crops)}
    if zoom:
        out["zoom_err"] = pooled(zoom)
    return out


def crop_only(outs, ins, spans):
    """Crop and ITF over valid pixels without truth (the maps need no truth)."""
    itfs, crops = [], []
    for a, b in spans:
        maps = C.output_maps(outs[a:b], ins[a:b])
        crops.append((min(float(np.mean(np.sqrt(np.abs(np.linalg.det(maps[:, :2, :2]))))), 1),
                      b - a))
        itfs.append((C.itf(outs[a:b], maps)[0], b - a - 1))
    return {"crop": sum(v * n for v, n in crops) / sum(n for _, n in crops),
            "itf": sum(v * n for v, n in itfs) / sum(n for _, n in itfs)}


def measure(clip_y4m, out_y4m, truth):
    """All metrics of one output (out_y4m None: the input itself). Runs in a worker process."""
    ins = C.read_y4m_luma(clip_y4m)
    h, w = ins[0].shape
    C.set_size("%dx%d" % (w, h))
    spans = shots(len(ins), truth)
    if out_y4m is None:
        m = image_metrics(ins, spans)
        if truth:
            g = np.array([np.vstack([np.reshape(r, (2, 3)), [0, 0, 1]]) for r in truth["g"]])
            m["jitter"] = pooled([(C.jitter(C.components(g[a:b])) ** 2, b - a - 2 * TRIM)
                                  for a, b in spans])
        return m
    outs = C.read_y4m_luma(out_y4m)
    if len(outs) != len(ins):
        return {"error": "%d frames written of %d" % (len(outs), len(ins))}
    m = image_metrics(outs, spans)
    m.update(truth_metrics(outs, ins, truth, spans) if truth else crop_only(outs, ins, spans))
    os.unlink(out_y4m)          # 0.35 MB a frame: the outputs are not kept
    return m


def y4m_frames(path):
    """Frames in a 4:2:0 Y4M file, from its size."""
    with open(path, "rb") as f:
        head = f.readline()
    tags = {t[:1]: t[1:] for t in head.split()[1:]}
    frame = int(tags[b"W"]) * int(tags[b"H"]) * 3 // 2 + len(b"FRAME\n")
    return (os.path.getsize(path) - len(head)) // frame


# ---- report --------------------------------------------------------------------------------

def cells(row, key, fmt, best=None):
    """One metric of every method as "a / b / c / d", the best in bold."""
    vals = [row.get(m, {}).get(key) for m in METHODS]
    known = [v for v in vals if v is not None and np.isfinite(v)]
    pick = (min if best == "min" else max)(known) if best and known else None
    out = []
    for v in vals:
        text = "–" if v is None or not np.isfinite(v) else fmt % v
        out.append("**%s**" % text if pick is not None and v == pick else text)
    return " / ".join(out)


def registration(stab, clip_y4m, truth, work, extra):
    """home-stab's own registrations (--lookahead 15, its CSV) against the truth, frame to frame:
    of the frames reported ok, still or restored, the mean corner error and how many are more than 2 px
    off (silent errors); the others are failures. Cuts, blank frames and the first frame are
    not counted."""
    csv_path = work / "registration.csv"
    subprocess.run([str(stab), "--quiet", "--lookahead", "15", "--fixed-crop", "--csv",
                    str(csv_path)] + extra + [str(clip_y4m), "-"],
                   stdout=subprocess.DEVNULL, check=True)
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    g = [np.vstack([np.reshape(r, (2, 3)), [0, 0, 1]]) for r in truth["g"]]
    skip = set(truth["cuts"]) | set(truth["blank"]) | {b + 1 for b in truth["blank"]}
    corners = np.array([[0, 0, 1], [W - 1, 0, 1], [0, H - 1, 1], [W - 1, H - 1, 1]], float).T
    errs, failed = [], 0
    for k in range(1, min(len(rows), len(g))):
        if k in skip or rows[k]["status"] in ("first", "cut"):
            continue
        if rows[k]["status"] not in ("ok", "still", "restored", "bridged"):
            failed += 1
            continue
        path = [camera(float(rows[j]["raw_tx"]), float(rows[j]["raw_ty"]),
                       float(rows[j]["raw_angle"]), np.exp(float(rows[j]["raw_log_scale"])))
                for j in (k - 1, k)]
        got = path[1] @ np.linalg.inv(path[0])
        want = g[k] @ np.linalg.inv(g[k - 1])
        d = (got @ corners)[:2] - (want @ corners)[:2]
        errs.append(float(np.sqrt((d ** 2).sum(0)).mean()))
    e = np.array(errs)
    return {"frames": len(errs) + failed, "ok": len(errs), "failed": failed,
            "silent": int((e > 2.0).sum()), "mean": float(e.mean()) if len(e) else 0.0,
            "p95": float(np.percentile(e, 95)) if len(e) else 0.0}


def report(results, clips, meta):
    L = ["Per clip; every cell lists home-stab causal / home-stab --lookahead 15 / vidstab / "
         "deshake. jitter: px RMS against the truth (compare.py's); pc jitter: from phase "
         "correlation of consecutive frames (no truth needed); ITF: over valid pixels; ITF c70: "
         "over the central 70 %; follow: px RMS from the intended path (static clips: drift, "
         "px; zoom clips: also the zoom's error, %); crop: scale of the output window; speed: "
         "frames per CPU second and home-stab --lookahead 15 over vidstab.", "",
         "| clip | set | input jitter / pc | jitter px | pc jitter px | ITF dB | ITF c70 dB | "
         "follow px | crop | frames per CPU s | la15 / vidstab |",
         "|---|---|---|---|---|---|---|---|---|---|---|"]
    for clip in clips:
        r = results[clip.name]
        if "input" not in r:
            continue
        inp = r["input"]
        follow = cells(r, "drift" if r["static"] else "follow", "%.2f", "min")
        if any("zoom_err" in r.get(m, {}) for m in METHODS):
            follow += " (zoom %s %%)" % cells(r, "zoom_err", "%.2f", "min")
        try:
            ratio = "%.1fx" % (r["home-stab la15"]["cpu_fps"] / r["vidstab"]["cpu_fps"])
        except KeyError:
            ratio = "–"
        L.append("| %s | %s | %s / %.3f | %s | %s | %s | %s | %s | %s | %s | %s |" % (
            clip.name, clip.half, "%.2f" % inp["jitter"] if "jitter" in inp else "–",
            inp["pc_jitter"], cells(r, "jitter", "%.3f", "min"),
            cells(r, "pc_jitter", "%.3f", "min"), cells(r, "itf", "%.2f", "max"),
            cells(r, "itf_c70", "%.2f", "max"), follow, cells(r, "crop", "%.2f"),
            cells(r, "cpu_fps", "%.0f"), ratio))
    static = [c for c in clips if results[c.name]["static"]]
    if static:
        L += ["", "Static camera: drift px, and jitter added (output minus input; the truth's "
              "input jitter is 0) against the truth / by phase correlation:", "",
              "| clip | method | drift px | added jitter px (truth) | added pc jitter px |",
              "|---|---|---|---|---|"]
        for c in static:
            r = results[c.name]
            for m in METHODS:
                if m in r and "drift" in r[m]:
                    L.append("| %s | %s | %.2f | %.3f | %+.3f |" % (
                        c.name, m, r[m]["drift"], r[m]["jitter"],
                        r[m]["pc_jitter"] - r["input"]["pc_jitter"]))
    pairs = [(c, results.get(c.name.replace("occl_object", "occl_none")
                             .replace("occl_hand", "occl_none")))
             for c in clips if c.scenario == "occluder" and "none" not in c.name]
    pairs = [(c, base) for c, base in pairs if base]
    if pairs:
        L += ["", "Occluder: jitter with the occluder minus without (same camera), px, "
              "against the truth / by phase correlation:", "",
              "| clip | method | jitter without | with | difference | pc difference |",
              "|---|---|---|---|---|---|"]
        for c, base in pairs:
            r = results[c.name]
            for m in METHODS:
                if m in r and m in base and "jitter" in r[m]:
                    L.append("| %s | %s | %.3f | %.3f | %+.3f | %+.3f |" % (
                        c.name, m, base[m]["jitter"], r[m]["jitter"],
                        r[m]["jitter"] - base[m]["jitter"],
                        r[m]["pc_jitter"] - base[m]["pc_jitter"]))
    reg = [c for c in clips if "registration" in results[c.name]]
    if reg:
        L += ["", "Registration inside home-stab (--lookahead 15, its CSV's raw path) against the "
              "truth, frame to frame: ok counts the frames reported ok or still; silent: of "
              "those, more than 2 px off (mean corner error); failed: held frames (cuts and "
              "blank frames not counted).", "",
              "| clip | set | frames | failed % | silent % of ok | mean err px (ok) | p95 px |",
              "|---|---|---|---|---|---|---|"]
        for half in ("tuning", "test"):
            rows = [(c, results[c.name]["registration"]) for c in reg if c.half == half]
            for c, r in rows:
                L.append("| %s | %s | %d | %.1f | %.1f | %.3f | %.2f |" % (
                    c.name, half, r["frames"], 100.0 * r["failed"] / max(r["frames"], 1),
                    100.0 * r["silent"] / max(r["ok"], 1), r["mean"], r["p95"]))
            if rows:
                n = sum(r["frames"] for _, r in rows)
                ok = sum(r["ok"] for _, r in rows)
                L.append("| **all %s** | %s | %d | %.1f | %.1f | %.3f | |" % (
                    half, half, n, 100.0 * (n - ok) / max(n, 1),
                    100.0 * sum(r["silent"] for _, r in rows) / max(ok, 1),
                    sum(r["mean"] * r["ok"] for _, r in rows) / max(ok, 1)))
    L += ["", "Clips:", "", "| clip | set | scenario | what | source | frames |",
          "|---|---|---|---|---|---|"]
    for c in clips:
        L.append("| %s | %s | %s | %s | %s | %d |" % (c.name, c.half, c.scenario, c.why,
                                                      c.source, results[c.name]["frames"]))
    L += ["", "Run: %s" % ", ".join("%s %s" % kv for kv in meta.items())]
    return "\n".join(L) + "\n"


def speed_run(ctx, clips, chosen, methods, work, repeat, label):
    """Frames per CPU second of each method on each clip: the methods in turn, repeat times, one
    process at a time and no measurement beside them (the quality run measures outputs in
    parallel, which loads the machine while it times); the fastest run of each counts."""
    rows, t0 = {}, time.time()
    for clip in clips:
        y4m, _ = ctx.render(clip)
        n = y4m_frames(y4m)
        best = {}
        for _ in range(repeat):
            for m in chosen:
                out = work / "out" / ("speed_%s.y4m" % m.replace(" ", "_"))
                cpu = sum(C.run(cmd)[1] for cmd in methods[m](str(y4m), str(out)))
                best[m] = min(best.get(m, cpu), cpu)
                for f in (out, Path(str(out) + ".trf")):
                    if f.exists():
                        f.unlink()
        rows[clip.name] = {"frames": n, **{m: n / best[m] for m in chosen}}
        print("%-24s %4d frames, %s (%.0f s)" % (clip.name, n, ", ".join(
            "%s %.0f" % (m, rows[clip.name][m]) for m in chosen), time.time() - t0), flush=True)
    head = "| clip | frames | " + " | ".join(chosen) + " |"
    L = ["Frames per CPU second (the fastest of %d runs, methods in turn, one process at a "
         "time)." % repeat, "", head, "|" + "---|" * (len(chosen) + 2)]
    ratio = "home-stab la15" in chosen and "vidstab" in chosen
    if ratio:
        L[2] += " la15 / vidstab |"
        L[3] += "---|"
    for name, r in rows.items():
        line = "| %s | %d | " % (name, r["frames"]) + " | ".join("%.0f" % r[m] for m in chosen)
        L.append(line + (" | %.1fx |" % (r["home-stab la15"] / r["vidstab"]) if ratio else " |"))
    if ratio:
        x = sorted(r["home-stab la15"] / r["vidstab"] for r in rows.values())
        L += ["", "la15 / vidstab: %.1f-%.1fx, median %.1fx" % (x[0], x[-1], x[len(x) // 2])]
    L += ["", "Run: commit %s, load %s, wall %.0f s" % (
        label, " ".join("%.1f" % v for v in os.getloadavg()), time.time() - t0)]
    (work / "speed.md").write_text("\n".join(L) + "\n")
    (work / "speed.json").write_text(json.dumps(rows, indent=1))
    print("\n".join(L))


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--set", default="all", choices=["tuning", "test", "all"])
    ap.add_argument("--quick", action="store_true", help="four short clips (under 3 min)")
    ap.add_argument("--clips", default="", help="comma-separated clip names (see the report)")
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default=None,
                    help="work directory (default BUILD/bench-stab-realworld)")
    ap.add_argument("--cache", default=os.environ.get("HOME_EVAL_CACHE",
                                                      str(REPO / "build/eval-cache")),
                    help="Debian packages and photographs (bench/eval's cache)")
    ap.add_argument("--methods", default=",".join(METHODS))
    ap.add_argument("--stab-args", default="", help="extra home-stab options")
    ap.add_argument("--jobs", type=int, default=2, help="processes measuring the outputs")
    ap.add_argument("--registration-only", action="store_true",
                    help="only home-stab's registrations against the truth (no methods)")
    ap.add_argument("--speed", type=int, default=0, metavar="N",
                    help="speed only: each method N times a clip, in turn, with nothing "
                         "measured beside them; frames per CPU second of the fastest run")
    args = ap.parse_args()
    build = REPO / args.build
    work = Path(args.out) if args.out else build / "bench-stab-realworld"
    stab = build / "bin/home-stab"
    for tool in (stab, build / "bin/home-stab-clip"):
        if not tool.exists():
            sys.exit("%s missing: run make BUILD=%s first" % (tool, args.build))
    methods = C.method_commands(stab, args.stab_args.split())
    chosen = [m.strip() for m in args.methods.split(",")]
    for m in chosen:
        if m not in methods:
            sys.exit("unknown method %r (known: %s)" % (m, ", ".join(methods)))
    clips = [c for c in catalogue() if args.set in ("all", c.half)]
    if args.quick:
        clips = [c if c.scenario == "real" else dataclasses.replace(c, frames=60)
                 for c in clips if c.quick]
    if args.clips:
        names = args.clips.split(",")
        unknown = set(names) - {c.name for c in clips}
        if unknown:
            sys.exit("unknown clips %s (known: %s)" % (", ".join(sorted(unknown)),
                                                       ", ".join(c.name for c in clips)))
        clips = [c for c in clips if c.name in names]
    from common import git_describe
    ctx = Context(work, Path(args.cache), build)
    (work / "out").mkdir(parents=True, exist_ok=True)
    if args.speed:
        speed_run(ctx, clips, chosen, methods, work, args.speed, git_describe(build))
        return
    results, pending = {}, []
    t0 = time.time()
    with concurrent.futures.ProcessPoolExecutor(max(args.jobs, 1)) as pool:
        for clip in clips:
            y4m, truth = ctx.render(clip)
            n = y4m_frames(y4m)
            results[clip.name] = {"frames": n, "static": bool(truth and truth["static"])}
            if truth:
                results[clip.name]["registration"] = registration(
                    stab, y4m, truth, ctx.clip_dir(clip), args.stab_args.split())
            if args.registration_only:
                continue
            pending.append((clip.name, "input", pool.submit(measure, y4m, None, truth)))
            for m in chosen:
                out = work / "out" / ("%s_%s.y4m" % (clip.name, m.replace(" ", "_")))
                times = [C.run(cmd) for cmd in methods[m](str(y4m), str(out))]
                speed = {"fps": n / sum(t[0] for t in times),
                         "cpu_fps": n / sum(t[1] for t in times)}
                results[clip.name][m] = speed
                pending.append((clip.name, m, pool.submit(measure, y4m, out, truth)))
                trf = Path(str(out) + ".trf")
                if trf.exists():
                    trf.unlink()
            print("%-24s %4d frames, stabilised (%.0f s)" % (clip.name, n, time.time() - t0),
                  flush=True)
        for name, m, fut in pending:
            got = fut.result()
            if "error" in got:
                sys.exit("%s, %s: %s" % (name, m, got["error"]))
            results[name].setdefault(m, {}).update(got)
    meta = {"commit": git_describe(REPO), "date": time.strftime("%Y-%m-%d"),
            "load": "%.1f %.1f %.1f" % os.getloadavg(), "wall": "%.0f s" % (time.time() - t0),
            "stab-args": repr(args.stab_args)}
    text = report(results, clips, meta)
    print("\n" + text)
    (work / "results.md").write_text(text)
    (work / "results.json").write_text(json.dumps({"meta": meta, "clips": results}, indent=1))


if __name__ == "__main__":
    main()
