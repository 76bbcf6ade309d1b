"""Data for the trust evaluation: still pairs, consecutive frames, static-camera
clips.  Everything is generated from names (common.rng_for), written under
<cache>/trust/<set>/... as PGM files with the truth beside them, and reused
when it is already there (GEN marks the generator's version: bump it when the
generation changes, and the cache regenerates).

Still pairs follow pairs_eval.py's protocol (854x480 cover, corners moved in
[-p, p], central 640x360 crops, texture decay, noise sigma 2.5); the tuning
set's line-rich and texture-decay pairs are exactly `make eval`'s pairs
(pairs_eval.make_pair with the same names).  Low light replaces the protocol's
noise by scenes.low_light on each crop.

Consecutive frames: video_eval.py's hand-held camera, its path slowed to about
3 px of motion a frame (PATH_FRAMES below), under four conditions:
  day          noise sigma 2.5
  low_light    scenes.low_light on each frame (brightness 10-25 %, shot + read noise)
  motion_blur  each frame the mean of 7 renders over the whole frame interval
  shake5       the hand-shake jitter 5x larger
  lens_shading day, through a lens whose illumination falls off as (r / r_corner)^2 by 10-40 %
               at the corners (trust_catalogue.LENS_SHADING), before the sensor noise

Static camera: a static background with moving textured shapes (their areas
add up to 15-25 % of the frame; the sealed set's 13-26 %, with salted seeds:
trust_catalogue.STATIC_COVER and STATIC_SALT), noise sigma 2.5, then an H.264
round trip (libx264, CRF 23, preset medium, yuv420p, 30 fps) through ffmpeg
(libx264's default GOP of 250 frames; condition "gop30": an I-frame every 30
frames, as cameras write; condition "raw": no encoder); the decoded Y4M is what
home-stab reads and its Y planes are the PGMs home-register reads.
"""
import bz2
import json
import subprocess
from pathlib import Path

import cv2
import numpy as np

import pairs_eval
import scenes
import video_eval
from common import (CROP_H, CROP_W, FULL_H, FULL_W, NOISE_SIGMA, corner_error, cover_resize,
                    rng_for, to_u8, write_pgm)
from data import Library

GEN = 2
PATH_FRAMES = 200            # video_eval's is 60 (about 7 px a frame); 200 gives about 3
STATIC_CRF = 23
CAMERA_GOP = 30     # frames from one I-frame to the next in the "gop30" clips (a camera's)


class TrustLibrary(Library):
    """data.Library plus the test set's formats: PyWavelets' .npz, SciPy's
    face.dat (bz2-compressed raw 768x1024 RGB), and "FILE.rcc#K": the K-th WebP
    image (in file order) stored in a Qt resource file (GCompris's data)."""

    def fetch(self, photos):
        from data import Photo
        super().fetch([Photo(p.source, p.file.split("#")[0], p.why) for p in photos])

    def grey(self, photo):
        path = self.cache / "photos" / photo.source / photo.file
        if not (self.cache / "photos" / photo.source / photo.file.split("#")[0]).exists():
            self.fetch([photo])                  # on demand: a clip built on its own
        if "#" in photo.file:
            container, k = photo.file.split("#")
            img = rcc_webp(self.cache / "photos" / photo.source / container, int(k))
        elif path.suffix == ".npz":
            img = np.load(path)["data"].astype(np.float32)
        elif path.name == "face.dat":
            rgb = np.frombuffer(bz2.decompress(path.read_bytes()), np.uint8).reshape(768, 1024, 3)
            img = cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(np.float32)
        else:
            return super().grey(photo)
        if photo.crop:
            x, y, w, h = photo.crop
            img = img[y:y + h, x:x + w]
        return img


def rcc_webp(path, k):
    """The k-th WebP image in a Qt .rcc resource file, grey float32.  rcc stores
    already-compressed images as they are, so each is a whole RIFF/WEBP chunk."""
    import re
    import struct
    data = Path(path).read_bytes()
    for i, m in enumerate(re.finditer(rb"RIFF(....)WEBP", data, re.S)):
        if i == k:
            n = struct.unpack("<I", m.group(1))[0]
            img = cv2.imdecode(np.frombuffer(data, np.uint8, 8 + n, m.start()),
                               cv2.IMREAD_GRAYSCALE)
            if img is None:
                raise RuntimeError(f"{path}: WebP image {k} does not decode")
            return img.astype(np.float32)
    raise RuntimeError(f"{path} has no WebP image {k}")


def world(lib, item, w, h):
    """The item's picture covering w x h (before the pair's geometry), with its
    condition applied where it acts on the scene (fog, defocus)."""
    if item.photo:
        img = cover_resize(lib.grey(item.photo), w, h)
    else:
        kind, variant, seed = item.scene
        img = scenes.render(kind, variant, seed, w, h)
    if item.condition == "fog":
        img = scenes.fog(img, rng_for(f"fog|{item.name}"))
    elif item.condition == "defocus":
        img = scenes.defocus(img)
    return img


def _done(d):
    g = d / "gt.json"
    if not g.exists():
        return None
    try:
        j = json.loads(g.read_text())
    except ValueError:
        return None
    return j if j.get("gen") == GEN else None


# --------------------------------------------------------------------------
# Still pairs
# --------------------------------------------------------------------------
def low_light_pair(full, name, p, idx):
    """pairs_eval.make_pair's geometry with a low-light capture for each crop."""
    key = f"{name}|p{p}|{idx}"
    warped, Hc = pairs_eval.warp_full(full, key, p)
    ox, oy = pairs_eval.OX, pairs_eval.OY
    gain = scenes.low_light_params(rng_for(key + "|gain"))["gain"]
    noise = rng_for(key + "|lownoise")
    A, B = (scenes.low_light(im[oy:oy + CROP_H, ox:ox + CROP_W], gain, noise)
            for im in (full, warped))
    return A, B, Hc / Hc[2, 2]


def pair_plan(which, group, items, quick, catalogue):
    """[(item, p, alpha, idx)] for one group."""
    n = catalogue.PAIRS[which] if not quick else catalogue.QUICK["pairs"]
    if quick:
        items = items[:catalogue.QUICK["items_per_group"]]
    kind = dict((g, k) for g, _, k in catalogue.GROUPS)[group]
    plan = []
    for it in items:
        if kind == "p":
            ps = catalogue.QUICK["p"] if quick else pairs_eval.P_LIST
            plan += [(it, p, 0.0, i) for p in ps for i in range(n)]
        elif kind == "alpha":
            al = catalogue.QUICK["alpha"] if quick else pairs_eval.ALPHAS
            plan += [(it, pairs_eval.DECAY_P, a, i) for a in al for i in range(n)]
        else:
            m = n if quick else catalogue.CYCLE_PAIRS
            plan += [(it, catalogue.P_CYCLE[i % len(catalogue.P_CYCLE)], 0.0, i)
                     for i in range(m)]
    return plan


def row_label(group, label, p, alpha):
    if group == "line_rich":
        return f"e line-rich, p = {p}"
    if group == "decay":
        return f"f texture decay, α = {alpha:g}"
    return label


def build_pairs(lib, which, quick, root, catalogue, jobs=2):
    """Still-pair records of one set (generated where missing)."""
    from common import parallel_map
    groups = catalogue.still_groups(which)
    labels = {g: l for g, l, _ in catalogue.GROUPS}
    work = []                                      # per item: its pairs
    for group, items in groups.items():
        plan = pair_plan(which, group, items, quick, catalogue)
        by_item = {}
        for it, p, a, i in plan:
            by_item.setdefault(it, []).append((p, a, i))
        for it, settings in by_item.items():
            work.append((group, it, settings))

    def one(job):
        group, it, settings = job
        # the tuning set's photo groups are `make eval`'s own pairs (same names)
        if which == "tuning" and group in ("line_rich", "decay"):
            name = it.photo.name
        else:
            name = f"trust|{which}|{group}|{it.name}"
        full = None
        out = []
        for p, a, i in settings:
            d = root / which / "pairs" / group / it.name / f"p{p}_a{a:g}_i{i}"
            gt = _done(d)
            if gt is None:
                if full is None:
                    full = world(lib, it, FULL_W, FULL_H)
                if it.condition == "lowlight":
                    A, B, Ht = low_light_pair(full, name, p, i)
                else:
                    A, B, Ht = pairs_eval.make_pair(full, name, p, i, a)
                d.mkdir(parents=True, exist_ok=True)
                write_pgm(d / "A.pgm", A)
                write_pgm(d / "B.pgm", B)
                gt = {"gen": GEN, "H": Ht.ravel().tolist()}
                (d / "gt.json").write_text(json.dumps(gt))
            Ht = np.array(gt["H"]).reshape(3, 3)
            out.append({
                "set": which, "suite": "pairs", "group": group,
                "row": row_label(group, labels[group], p, a), "image": it.name,
                "source": it.source, "p": p, "alpha": a, "idx": i,
                "A": str(d / "A.pgm"), "B": str(d / "B.pgm"), "H_true": Ht.ravel().tolist(),
                "err_identity": corner_error(np.eye(3), Ht)})
        return out

    return [r for rs in parallel_map(one, work, jobs) for r in rs]


# --------------------------------------------------------------------------
# Consecutive frames
# --------------------------------------------------------------------------
class HandheldCamera(video_eval.Camera):
    """video_eval.Camera with a slower path (PATH_FRAMES) and a shake factor."""

    path_frames = PATH_FRAMES

    def __init__(self, key, n_frames, world_shape, shake=1.0):
        super().__init__(key, n_frames, world_shape)
        self.jitter = self.jitter * shake
        if shake > 1:                    # keep the shaken frame inside the world
            self.amp = self.amp * 0.6


def lens_shading(rng, falloff):
    """Illumination of a CROP_W x CROP_H sensor through a lens: 1 at the centre, 1 - s at the
    corners, s drawn uniformly from the range `falloff` (the (r / r_corner)^2 law)."""
    s = rng.uniform(*falloff)
    y, x = np.mgrid[0:CROP_H, 0:CROP_W].astype(np.float64)
    r2 = ((x - (CROP_W - 1) / 2) ** 2 + (y - (CROP_H - 1) / 2) ** 2) / (
        ((CROP_W - 1) / 2) ** 2 + ((CROP_H - 1) / 2) ** 2)
    return 1.0 - s * r2


def build_video(lib, which, quick, root, catalogue, frames, jobs=2):
    from common import parallel_map
    items = catalogue.video_scenes(which)
    if quick:
        items = items[:catalogue.QUICK["video_scenes"]]
    ww, wh = round(CROP_W * video_eval.WORLD_SCALE), round(CROP_H * video_eval.WORLD_SCALE)
    jobs_list = [(it, cond) for it in items for cond in catalogue.VIDEO_CONDITIONS]

    def one(job):
        it, cond = job
        d = root / which / "video" / cond / f"{it.name}_n{frames}"
        gt = _done(d)
        if gt is None:
            wld = world(lib, it, ww, wh)
            key = f"trust|{which}|video|{it.name}|{cond}"
            cam = HandheldCamera(key, frames, wld.shape, 5.0 if cond == "shake5" else 1.0)
            noise = rng_for(key + "|noise")
            gain = scenes.low_light_params(rng_for(key + "|gain"))["gain"]
            shading = lens_shading(rng_for(key + "|shading"), catalogue.LENS_SHADING)
            d.mkdir(parents=True, exist_ok=True)
            Ms = []
            for t in range(frames):
                if cond == "motion_blur":
                    # the exposure: poses along the straight line through M(t) with
                    # the central-difference velocity, over the whole frame interval,
                    # so the blur is symmetric about M(t) and M(t) is the truth
                    vel = (cam.M(t + 1) - cam.M(t - 1)) / 2
                    img = np.mean([video_eval.render(wld, cam.M(t) + dt * vel) for dt in
                                   np.linspace(-0.5, 0.5, video_eval.BLUR_SAMPLES)], axis=0)
                else:
                    img = video_eval.render(wld, cam.M(t))
                if cond == "lens_shading":
                    img = img * shading
                if cond == "low_light":
                    f = scenes.low_light(img, gain, noise)
                else:
                    f = to_u8(img + noise.normal(0, NOISE_SIGMA, img.shape))
                write_pgm(d / f"{t:03d}.pgm", f)
                Ms.append(cam.M(t))
            Hs = []
            for t in range(1, frames):
                Ht = np.linalg.inv(Ms[t]) @ Ms[t - 1]
                Hs.append((Ht / Ht[2, 2]).ravel().tolist())
            gt = {"gen": GEN, "H": Hs}
            (d / "gt.json").write_text(json.dumps(gt))
        out = []
        for t in range(1, frames):
            Ht = np.array(gt["H"][t - 1]).reshape(3, 3)
            out.append({
                "set": which, "suite": "video", "group": cond, "row": cond,
                "image": it.name, "source": it.source, "idx": t,
                "A": str(d / f"{t - 1:03d}.pgm"), "B": str(d / f"{t:03d}.pgm"),
                "H_true": Ht.ravel().tolist(), "err_identity": corner_error(np.eye(3), Ht)})
        return out

    return [r for rs in parallel_map(one, jobs_list, jobs) for r in rs]


# --------------------------------------------------------------------------
# Static camera, moving objects
# --------------------------------------------------------------------------
def _objects(lib, key, textures, frames, cover=(0.15, 0.25)):
    """Moving textured shapes: each a (texture, mask) sprite with a path; their
    areas add up to a share of the frame drawn from the range `cover`."""
    rng = rng_for(key + "|objects")
    n = int(rng.integers(3, 5))
    cover = rng.uniform(*cover)               # their areas add up to this share at most
    areas = rng.dirichlet(np.ones(n)) * cover * CROP_W * CROP_H
    objs = []
    for k in range(n):
        tex_photo = textures[k % len(textures)]
        aspect = rng.uniform(0.6, 1.6)
        shape = ["ellipse", "rect", "poly"][int(rng.integers(3))]
        # mask area: ellipse pi/4 of its box, rect 1, polygon ~0.6 of it
        fill = {"ellipse": np.pi / 4, "rect": 1.0, "poly": 0.6}[shape]
        bw = np.sqrt(areas[k] / fill * aspect)
        bh = bw / aspect
        S = int(np.ceil(np.hypot(bw, bh))) + 4      # sprite canvas (rotation-safe)
        S += S % 2
        tex = cover_resize(lib.grey(tex_photo), S, S)
        mask = np.zeros((S, S), np.float32)
        c = (S // 2, S // 2)
        if shape == "ellipse":
            cv2.ellipse(mask, c, (int(bw / 2), int(bh / 2)), 0, 0, 360, 1.0, -1)
        elif shape == "rect":
            cv2.rectangle(mask, (int(c[0] - bw / 2), int(c[1] - bh / 2)),
                          (int(c[0] + bw / 2), int(c[1] + bh / 2)), 1.0, -1)
        else:
            ang = np.sort(rng.uniform(0, 2 * np.pi, 6))
            pts = np.c_[c[0] + bw / 2 * np.cos(ang), c[1] + bh / 2 * np.sin(ang)]
            cv2.fillPoly(mask, [pts.astype(np.int32)], 1.0)
        mask = cv2.GaussianBlur(mask, (0, 0), 0.7)
        start = rng.uniform([0.1 * CROP_W, 0.1 * CROP_H], [0.9 * CROP_W, 0.9 * CROP_H])
        speed = rng.uniform(1.0, 4.0)
        heading = rng.uniform(0, 2 * np.pi)
        objs.append({"tex": tex, "mask": mask, "S": S, "start": start,
                     "vel": speed * np.array([np.cos(heading), np.sin(heading)]),
                     "spin": rng.uniform(-1.0, 1.0), "wobble": rng.uniform(0, 2 * np.pi)})
    return objs


def _bounce(x, lo, hi):
    span = hi - lo
    y = np.mod(x - lo, 2 * span)
    return lo + np.where(y > span, 2 * span - y, y)


def render_static(bg, objs, t):
    img = bg.copy()
    for o in objs:
        pos = o["start"] + o["vel"] * t + 6 * np.sin(0.1 * t + o["wobble"])
        x = _bounce(pos[0], 0.05 * CROP_W, 0.95 * CROP_W)
        y = _bounce(pos[1], 0.05 * CROP_H, 0.95 * CROP_H)
        S = o["S"]
        A = cv2.getRotationMatrix2D((S / 2, S / 2), o["spin"] * t, 1.0)
        A[:, 2] += [x - S / 2, y - S / 2]
        tex = cv2.warpAffine(o["tex"], A, (CROP_W, CROP_H), flags=cv2.INTER_LINEAR)
        m = cv2.warpAffine(o["mask"], A, (CROP_W, CROP_H), flags=cv2.INTER_LINEAR)
        img = img * (1 - m) + tex * m
    return img


def write_y4m(path, frames):
    """Grey frames as 4:2:0 Y4M with neutral chroma, 30 fps."""
    h, w = frames[0].shape
    chroma = np.full(w * h // 2, 128, np.uint8).tobytes()
    with open(path, "wb") as f:
        f.write(b"YUV4MPEG2 W%d H%d F30:1 Ip A1:1 C420jpeg\n" % (w, h))
        for fr in frames:
            f.write(b"FRAME\n" + np.ascontiguousarray(fr, np.uint8).tobytes() + chroma)


def read_y4m_luma(path):
    """Y planes of a 4:2:0 Y4M file, as uint8 arrays."""
    data = Path(path).read_bytes()
    head_end = data.index(b"\n")
    fields = data[:head_end].split()
    w = int(next(f[1:] for f in fields if f.startswith(b"W")))
    h = int(next(f[1:] for f in fields if f.startswith(b"H")))
    pos, out = head_end + 1, []
    size = w * h * 3 // 2
    while pos < len(data):
        nl = data.index(b"\n", pos)
        pos = nl + 1
        out.append(np.frombuffer(data, np.uint8, w * h, pos).reshape(h, w))
        pos += size
    return out


def _moving_share(bg, objs, frames):
    """The largest share of the frame the objects change (every 25th frame of
    the full clip, noise-free)."""
    return max(float(np.mean(np.abs(render_static(bg, objs, t) - bg) > 0.5))
               for t in range(0, max(frames, 300), 25))


def _static_objects(lib, key, textures, frames, bg, catalogue, which):
    """_objects for a clip, redrawn (key + "|redraw<k>") until the moving share
    lies in catalogue.STATIC_SHARE: objects leaving the frame or overlapping can
    leave less moving than their areas add up to.  The first draw stands when it
    fits, so the clips made before this check are unchanged."""
    cover = getattr(catalogue, "STATIC_COVER", {}).get(which, (0.15, 0.25))
    lo, hi = getattr(catalogue, "STATIC_SHARE", (0.0, 1.0))
    for k in range(20):
        objs = _objects(lib, key + (f"|redraw{k}" if k else ""), textures, frames, cover)
        if lo <= _moving_share(bg, objs, frames) <= hi:
            return objs
    raise RuntimeError(f"{key}: no draw of objects moves {lo:.0%}-{hi:.0%} of the frame")


def build_static(lib, which, quick, root, catalogue, frames, jobs=2):
    """Records of every consecutive pair (truth: identity) and the clips' y4m paths."""
    from common import parallel_map
    clips = catalogue.static_clips(which)
    if quick:
        clips = clips[:catalogue.QUICK["static_clips"]]

    def one(job):
        bg_item, textures = job
        d = root / which / "static" / f"{bg_item.name}_n{frames}"
        y4m = d / "clip.y4m"
        gt = _done(d)
        if gt is None or not y4m.exists():
            d.mkdir(parents=True, exist_ok=True)
            key = f"trust|{which}|static|{bg_item.name}" + \
                getattr(catalogue, "STATIC_SALT", {}).get(which, "")
            bg = world(lib, bg_item, CROP_W, CROP_H)
            objs = _static_objects(lib, key, textures, frames, bg, catalogue, which)
            noise = rng_for(key + "|noise")
            raw = bg_item.condition == "raw"   # a live camera's frames: no encoder
            mp4 = d / "clip.mp4"
            if not raw:
                enc = subprocess.Popen(
                    ["ffmpeg", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "gray",
                     "-s", f"{CROP_W}x{CROP_H}", "-r", "30", "-i", "-", "-c:v", "libx264",
                     "-preset", "medium", "-crf", str(STATIC_CRF)] +
                    (["-g", str(CAMERA_GOP)] if bg_item.condition == "gop30" else []) +
                    ["-pix_fmt", "yuv420p", str(mp4)], stdin=subprocess.PIPE)
            cover, raw_frames = [], []
            for t in range(frames):
                img = render_static(bg, objs, t)
                f = to_u8(img + noise.normal(0, NOISE_SIGMA, img.shape))
                if raw:
                    raw_frames.append(f)
                else:
                    enc.stdin.write(f.tobytes())
                if t % 25 == 0:
                    cover.append(float(np.mean(np.abs(img - bg) > 0.5)))
            if raw:
                write_y4m(y4m, raw_frames)
            else:
                enc.stdin.close()
                if enc.wait() != 0:
                    raise RuntimeError("ffmpeg (libx264 encode) failed")
                subprocess.run(["ffmpeg", "-loglevel", "error", "-y", "-i", str(mp4),
                                "-f", "yuv4mpegpipe", "-pix_fmt", "yuv420p", str(y4m)],
                               check=True)
            lumas = read_y4m_luma(y4m)
            if len(lumas) != frames:
                raise RuntimeError(f"{y4m}: {len(lumas)} frames decoded, {frames} encoded")
            for t, f in enumerate(lumas):
                write_pgm(d / f"{t:03d}.pgm", np.ascontiguousarray(f))
            gt = {"gen": GEN, "frames": frames, "crf": None if raw else STATIC_CRF,
                  "kbps": (CROP_W * CROP_H * 8 * 30 / 1000 if raw
                           else mp4.stat().st_size * 8 / (frames / 30) / 1000),
                  "moving_share_max": max(cover)}
            (d / "gt.json").write_text(json.dumps(gt))
        recs = [{"set": which, "suite": "static", "group": bg_item.name, "row": bg_item.name,
                 "image": bg_item.name, "source": bg_item.source, "idx": t,
                 "A": str(d / f"{t - 1:03d}.pgm"), "B": str(d / f"{t:03d}.pgm"),
                 "H_true": np.eye(3).ravel().tolist(), "err_identity": 0.0}
                for t in range(1, frames)]
        clip = {"set": which, "name": bg_item.name, "why": bg_item.why,
                "source": bg_item.source, "textures": [p.file for p in textures],
                "y4m": str(y4m), "frames": frames, "kbps": gt["kbps"],
                "moving_share_max": gt["moving_share_max"]}
        return recs, clip

    outs = parallel_map(one, clips, jobs)
    return [r for rs, _ in outs for r in rs], [c for _, c in outs]
