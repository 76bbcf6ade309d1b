#!/usr/bin/env python3
"""Synthetic-pair evaluation of HOME (via its CLI) against OpenCV ORB.

Reproduces the HOME paper's synthetic protocol:
  * grey image, scaled to cover 854x480 and centre-cropped;
  * ground truth: the 4 corners of the 854x480 frame shifted uniformly in
    [-p, p] per coordinate, the image warped by that homography (bilinear);
  * the central 640x360 of original (A) and warped (B) kept, so
    H_crop = T^-1 H T with T = translation by the crop offset (107, 60);
  * Gaussian noise sigma 2.5 added to both, clipped, uint8.
  * "linear" set: p in {10..60}; "normal" set: texture decay
    I' = I + alpha (128 - I) at p = 20 for alpha in {0, .4, .6, .8, .9, .95}.
H maps A's pixel coordinates to B's (x right, y down, top-left pixel centre
at (0,0), which is also OpenCV's convention).

Error = mean distance between the 4 crop corners mapped by the estimated and
the true H.  A failure is scored with the identity's error.

Images come from Debian's opencv-doc package (examples/data), fetched into the
cache (default build/eval-cache, env HOME_EVAL_CACHE) with `apt-get download`
(fallback: an existing /tmp/opencv-doc*.deb) and unpacked with `dpkg -x`.

Usage (from the repository root):
  python3 bench/eval/pairs_eval.py                 # full run
  python3 bench/eval/pairs_eval.py --quick --jobs 2
  python3 bench/eval/pairs_eval.py --methods orb,akaze,identity --sets normal
Per-pair results go to <cache>/results/pairs_eval.{json,csv}.
"""
import argparse
import concurrent.futures
import csv
import glob
import gzip
import json
import os
import shlex
import subprocess
import sys
import time
import zlib
from pathlib import Path

import cv2
import numpy as np

REPO = Path(__file__).resolve().parents[2]

# Protocol constants (paper).
FW, FH = 854, 480            # full frame
CW, CH = 640, 360            # evaluated crop
OX, OY = (FW - CW) // 2, (FH - CH) // 2   # crop offset (107, 60)
P_LIST = [10, 20, 30, 40, 50, 60]
ALPHAS = [0.0, 0.4, 0.6, 0.8, 0.9, 0.95]
DECAY_P = 20
NOISE_SIGMA = 2.5
PAIRS_PER_IMAGE = 5
MIN_INLIERS = 20             # paper's failure rule, with det(H[:2,:2]) > 0
CORNERS = np.array([[0, 0], [CW - 1, 0], [0, CH - 1], [CW - 1, CH - 1]], float)

# Image sets from opencv-doc examples/data.  The first four of each list are
# the --quick subset, so they are chosen to be representative.
LINEAR = [  # strong straight structures: facades, grids, chessboards, PCB
    "building.jpg", "sudoku.png", "left01.jpg", "board.jpg",
    "right05.jpg", "left12.jpg", "leuvenA.jpg", "home.jpg",
    "box_in_scene.png", "Blender_Suzanne1.jpg",
]
NORMAL = [  # texture-rich natural / painted content
    "fruits.jpg", "baboon.jpg", "graf1.png", "aero1.jpg",
    "starry_night.jpg", "aloeL.jpg", "rubberwhale1.png", "squirrel_cls.jpg",
    "butterfly.jpg", "chicky_512.png",
]
DATA_SUBDIR = "usr/share/doc/opencv-doc/examples/data"


# --------------------------------------------------------------------------
# Images
# --------------------------------------------------------------------------
def find_images(root, names):
    """Map wanted basenames to files under root (plain or .gz)."""
    found = {}
    for dirpath, _, files in os.walk(root):
        for f in files:
            base = f[:-3] if f.endswith(".gz") else f
            if base in names and base not in found:
                found[base] = Path(dirpath) / f
    return found


def ensure_images(cache, names):
    root = cache / "opencv-doc"
    found = find_images(root, names)
    if found:
        return found
    cache.mkdir(parents=True, exist_ok=True)
    debs = sorted(cache.glob("opencv-doc_*.deb"))
    if not debs:
        print("fetching opencv-doc with apt-get download ...", file=sys.stderr)
        try:
            subprocess.run(["apt-get", "download", "opencv-doc"], cwd=cache,
                           timeout=600, check=False)
        except (OSError, subprocess.TimeoutExpired) as e:
            print(f"apt-get download failed: {e}", file=sys.stderr)
        debs = sorted(cache.glob("opencv-doc_*.deb"))
    if not debs:  # offline machine: accept a .deb someone left in /tmp
        debs = sorted(Path(p) for p in glob.glob("/tmp/opencv-doc*.deb"))
    if not debs:
        sys.exit("cannot obtain opencv-doc .deb (apt-get download failed, "
                 "none in /tmp)")
    subprocess.run(["dpkg", "-x", str(debs[-1]), str(root)], check=True)
    return find_images(root, names)


def load_grey(path):
    data = path.read_bytes()
    if path.suffix == ".gz":
        data = gzip.decompress(data)
    img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise RuntimeError(f"cannot decode {path}")
    return img


def cover_crop(img):
    """Scale so the image covers FWxFH, then centre-crop; float32."""
    h, w = img.shape
    s = max(FW / w, FH / h)
    nw, nh = max(FW, round(w * s)), max(FH, round(h * s))
    interp = cv2.INTER_AREA if s < 1 else cv2.INTER_CUBIC
    img = cv2.resize(img, (nw, nh), interpolation=interp).astype(np.float32)
    x0, y0 = (nw - FW) // 2, (nh - FH) // 2
    return np.clip(img[y0:y0 + FH, x0:x0 + FW], 0, 255)


# --------------------------------------------------------------------------
# Pair synthesis
# --------------------------------------------------------------------------
def rng_for(key):
    # Seed from the pair's identity, not from run order, so any subset
    # (--quick, --p, --sets) reproduces exactly the same pairs.
    return np.random.default_rng(zlib.crc32(key.encode()))


def make_pair(full, name, p, idx, alpha=0.0):
    """Return (A, B, H_crop) for one pair.  The geometry and the noise depend
    on (image, p, idx) only, so an alpha sweep varies texture alone."""
    key = f"{name}|p{p}|{idx}"
    src = np.float32([[0, 0], [FW - 1, 0], [0, FH - 1], [FW - 1, FH - 1]])
    dst = src + rng_for(key).uniform(-p, p, (4, 2)).astype(np.float32)
    Hf = cv2.getPerspectiveTransform(src, dst)          # full A -> full B
    warped = cv2.warpPerspective(full, Hf, (FW, FH), flags=cv2.INTER_LINEAR,
                                 borderMode=cv2.BORDER_REFLECT)
    T = np.array([[1, 0, OX], [0, 1, OY], [0, 0, 1]], float)
    Hc = np.linalg.inv(T) @ Hf @ T                       # crop A -> crop B
    Hc /= Hc[2, 2]
    nrng = rng_for(key + "|noise")
    out = []
    for im in (full, warped):
        im = im[OY:OY + CH, OX:OX + CW]
        im = im + alpha * (128.0 - im)                   # texture decay
        im = im + nrng.normal(0, NOISE_SIGMA, im.shape)
        out.append(np.clip(np.rint(im), 0, 255).astype(np.uint8))
    return out[0], out[1], Hc


def write_pgm(path, img):
    h, w = img.shape
    path.write_bytes(b"P5\n%d %d\n255\n" % (w, h) + img.tobytes())


# --------------------------------------------------------------------------
# Scoring
# --------------------------------------------------------------------------
def project(H, pts):
    q = np.c_[pts, np.ones(len(pts))] @ H.T
    return q[:, :2] / q[:, 2:3]


def corner_error(H_est, H_true):
    with np.errstate(all="ignore"):
        d = np.linalg.norm(project(H_est, CORNERS) - project(H_true, CORNERS),
                           axis=1).mean()
    return float(d) if np.isfinite(d) else float("inf")


def passes_paper_rule(H, inliers):
    """Paper's failure rule: >= 20 inliers and an orientation-preserving
    top-left 2x2 once h22 is normalised to 1."""
    if H is None or not np.all(np.isfinite(H)) or abs(H[2, 2]) < 1e-12:
        return False
    Hn = H / H[2, 2]
    return inliers >= MIN_INLIERS and np.linalg.det(Hn[:2, :2]) > 0


# --------------------------------------------------------------------------
# Methods.  Each returns a dict with at least "status" ("ok" or a failure
# reason) and, when available, "H" (3x3 ndarray), "inliers", "matches", "ms".
# --------------------------------------------------------------------------
def run_home(pair, args):
    cmd = [args.home] + shlex.split(args.home_args) + [pair["A"], pair["B"]]
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True,
                           timeout=args.timeout)
    except subprocess.TimeoutExpired:
        return {"status": "timeout"}
    except OSError as e:
        return {"status": "error", "detail": str(e)}
    wall = (time.perf_counter() - t0) * 1e3
    if r.returncode == 2:
        return {"status": "bad_input", "detail": r.stderr.strip()[-500:]}
    lines = [l for l in r.stdout.splitlines() if l.lstrip().startswith("{")]
    try:
        j = json.loads(lines[-1])
    except (IndexError, ValueError):
        return {"status": "error",
                "detail": f"rc={r.returncode} no JSON; {r.stderr.strip()[-300:]}"}
    cli_ms = j.get("ms") if isinstance(j.get("ms"), dict) else {}
    res = {"matches": j.get("matches"), "inliers": j.get("inliers"),
           "keypoints": j.get("keypoints"), "cli_ms": cli_ms,
           "ms": cli_ms.get("total", wall), "wall_ms": wall}
    if not j.get("ok"):
        res["status"] = "fail"
        return res
    H = np.asarray(j.get("H", []), float)
    if H.size != 9 or not np.all(np.isfinite(H)):
        res.update(status="error", detail=f"bad H {j.get('H')}")
        return res
    res["H"] = H.reshape(3, 3)
    res["status"] = "ok"  # HOME's own flag governs ...
    # ... but record whether the paper's rule would have rejected it.
    res["paper_rule_ok"] = bool(passes_paper_rule(res["H"], res["inliers"] or 0))
    return res


def make_feature_method(make_detector, norm):
    det = make_detector()
    bf = cv2.BFMatcher(norm)

    def run(pair, args):
        t0 = time.perf_counter()
        ka, da = det.detectAndCompute(pair["imgA"], None)
        kb, db = det.detectAndCompute(pair["imgB"], None)
        good = []
        if da is not None and db is not None and len(da) >= 2 and len(db) >= 2:
            for m in bf.knnMatch(da, db, k=2):
                if len(m) == 2 and m[0].distance < 0.75 * m[1].distance:
                    good.append(m[0])
        res = {"keypoints": [len(ka), len(kb)], "matches": len(good)}
        if len(good) < 4:
            res.update(status="few_matches", ms=(time.perf_counter() - t0) * 1e3)
            return res
        src = np.float32([ka[m.queryIdx].pt for m in good])   # A -> B
        dst = np.float32([kb[m.trainIdx].pt for m in good])
        H, mask = cv2.findHomography(src, dst, cv2.RANSAC)
        res["ms"] = (time.perf_counter() - t0) * 1e3
        if H is None:
            res["status"] = "ransac_none"
            return res
        res["H"], res["inliers"] = H, int(mask.sum())
        res["status"] = "ok" if passes_paper_rule(H, res["inliers"]) else "rule"
        return res
    return run


def run_identity(pair, args):
    return {"status": "ok", "H": np.eye(3), "ms": 0.0}


def get_methods(names):
    table = {
        "identity": run_identity,
        "home": run_home,
        "orb": lambda: make_feature_method(lambda: cv2.ORB_create(2000),
                                           cv2.NORM_HAMMING),
        "akaze": lambda: make_feature_method(cv2.AKAZE_create, cv2.NORM_HAMMING),
    }
    out = {}
    for n in names:
        if n not in table:
            sys.exit(f"unknown method {n!r}; choose from {', '.join(table)}")
        out[n] = table[n]() if n in ("orb", "akaze") else table[n]
    return out


# --------------------------------------------------------------------------
# Driver
# --------------------------------------------------------------------------
def build_pairs(args, cache, paths):
    """Synthesise all pairs, write A/B PGMs, return records."""
    pairs = []
    plan = []
    if "linear" in args.sets:
        plan += [("linear", n, p, 0.0) for n in args.linear for p in args.p]
    if "normal" in args.sets:
        plan += [("normal", n, DECAY_P, a) for n in args.normal for a in args.alpha]
    full_cache = {}
    for set_name, name, p, alpha in plan:
        if name not in paths:
            continue
        if name not in full_cache:
            full_cache[name] = cover_crop(load_grey(paths[name]))
        for idx in range(args.pairs):
            A, B, Ht = make_pair(full_cache[name], name, p, idx, alpha)
            tag = f"{Path(name).stem}_p{p}" + \
                (f"_a{alpha:.2f}" if set_name == "normal" else "") + f"_i{idx}"
            d = cache / "pairs" / set_name / tag
            d.mkdir(parents=True, exist_ok=True)
            write_pgm(d / "A.pgm", A)
            write_pgm(d / "B.pgm", B)
            (d / "gt.json").write_text(json.dumps({"H": Ht.ravel().tolist()}))
            pairs.append({"set": set_name, "image": name, "p": p,
                          "alpha": alpha, "idx": idx, "A": str(d / "A.pgm"),
                          "B": str(d / "B.pgm"), "imgA": A, "imgB": B,
                          "H_true": Ht, "err_identity": corner_error(np.eye(3), Ht),
                          "results": {}})
    return pairs


def evaluate(pairs, methods, args):
    for mname, fn in methods.items():
        t0 = time.perf_counter()
        if mname == "home" and args.jobs > 1:
            with concurrent.futures.ThreadPoolExecutor(args.jobs) as ex:
                outs = list(ex.map(lambda pr: fn(pr, args), pairs))
        else:
            outs = []
            for pr in pairs:
                try:
                    outs.append(fn(pr, args))
                except cv2.error as e:  # an exception is a failure, not a crash
                    outs.append({"status": "error", "detail": str(e)[:300]})
        for pr, res in zip(pairs, outs):
            ok = res["status"] == "ok"
            res["err"] = corner_error(res["H"], pr["H_true"]) if ok \
                else pr["err_identity"]
            pr["results"][mname] = res
        print(f"# {mname}: {len(pairs)} pairs in {time.perf_counter() - t0:.1f} s",
              file=sys.stderr)
        bad = [pr for pr, r in zip(pairs, outs) if r["status"] == "bad_input"]
        if bad:
            print(f"WARNING: {mname} rejected {len(bad)} inputs as bad (exit 2), "
                  f"e.g. {bad[0]['A']}", file=sys.stderr)


def summarise(pairs, methods, set_name, key, label):
    rows = [pr for pr in pairs if pr["set"] == set_name]
    if not rows:
        return
    imgs = sorted({pr["image"] for pr in rows})
    print(f"\n== {set_name} set ({len(imgs)} images): error in px, "
          f"{'p=' + str(DECAY_P) + ', ' if key == 'alpha' else ''}sweep over {label}")
    print(f"{label:>6} {'method':<9} {'n':>4} {'mean':>8} {'median':>8} "
          f"{'mean_ok':>8} {'fail%':>6} {'ms_med':>7}  failures")
    for v in sorted({pr[key] for pr in rows}):
        sel = [pr for pr in rows if pr[key] == v]
        for m in methods:
            rs = [pr["results"][m] for pr in sel]
            err = np.array([r["err"] for r in rs])
            ok = np.array([r["status"] == "ok" for r in rs])
            ms = [r["ms"] for r in rs if r.get("ms") is not None]
            # Failure reasons, so a crashing CLI is not mistaken for a
            # method that honestly reports failure.
            reasons = {}
            for r in rs:
                if r["status"] != "ok":
                    reasons[r["status"]] = reasons.get(r["status"], 0) + 1
            note = " ".join(f"{k}:{n}" for k, n in sorted(reasons.items()))
            if m == "home":  # cross-check HOME's ok results with paper's rule
                n_x = sum(1 for r in rs if r["status"] == "ok"
                          and not r.get("paper_rule_ok", True))
                if n_x:
                    note += f" {n_x} ok but fail paper rule"
            if m == "identity":
                fail = "-"
            else:
                fail = f"{100 * (1 - ok.mean()):.0f}"
            mean_ok = f"{err[ok].mean():8.2f}" if ok.any() else f"{'-':>8}"
            ms_s = f"{np.median(ms):7.1f}" if ms else f"{'-':>7}"
            vs = f"{v:g}"
            print(f"{vs:>6} {m:<9} {len(rs):>4} {err.mean():8.2f} "
                  f"{np.median(err):8.2f} {mean_ok} {fail:>6} {ms_s}  {note}")


def dump(pairs, methods, cache):
    out = cache / "results"
    out.mkdir(parents=True, exist_ok=True)
    recs = []
    for pr in pairs:
        rec = {k: pr[k] for k in ("set", "image", "p", "alpha", "idx", "A", "B",
                                  "err_identity")}
        rec["H_true"] = pr["H_true"].ravel().tolist()
        rec["results"] = {}
        for m, r in pr["results"].items():
            r = dict(r)
            if "H" in r:
                r["H"] = np.asarray(r["H"]).ravel().tolist()
            rec["results"][m] = r
        recs.append(rec)
    (out / "pairs_eval.json").write_text(json.dumps(recs, indent=1))
    with open(out / "pairs_eval.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["set", "image", "p", "alpha", "idx", "method", "status",
                    "err", "err_identity", "matches", "inliers", "ms", "A", "B",
                    "H_true", "H_est"])
        for rec in recs:
            for m, r in rec["results"].items():
                w.writerow([rec["set"], rec["image"], rec["p"], rec["alpha"],
                            rec["idx"], m, r["status"], f"{r['err']:.4f}",
                            f"{rec['err_identity']:.4f}", r.get("matches"),
                            r.get("inliers"), r.get("ms"), rec["A"], rec["B"],
                            " ".join(f"{x:.9g}" for x in rec["H_true"]),
                            " ".join(f"{x:.9g}" for x in r.get("H", []))])
    return out


def print_worst(pairs, method, n):
    if n <= 0 or method not in pairs[0]["results"]:
        return
    worst = sorted(pairs, key=lambda pr: -pr["results"][method]["err"])[:n]
    print(f"\nworst {len(worst)} pairs for {method}:")
    for pr in worst:
        r = pr["results"][method]
        print(f"  {r['err']:8.2f}px {r['status']:<11} {pr['image']} p={pr['p']} "
              f"alpha={pr['alpha']:g} i={pr['idx']}  {Path(pr['A']).parent}")


def csv_list(conv):
    return lambda s: [conv(x) for x in s.split(",") if x]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--home", default=str(REPO / "build/bin/home-register"),
                    help="HOME CLI (default build/bin/home-register)")
    ap.add_argument("--home-args", default="",
                    help="extra arguments passed to the CLI before A.pgm B.pgm")
    ap.add_argument("--methods", type=csv_list(str), default="identity,home,orb",
                    help="comma list of identity,home,orb,akaze")
    ap.add_argument("--sets", type=csv_list(str), default="linear,normal")
    ap.add_argument("--p", type=csv_list(int), default=P_LIST,
                    help="corner perturbations for the linear set")
    ap.add_argument("--alpha", type=csv_list(float), default=ALPHAS,
                    help="texture decay values for the normal set")
    ap.add_argument("--pairs", type=int, default=PAIRS_PER_IMAGE)
    ap.add_argument("--images", type=int, default=None,
                    help="use only the first N images of each set")
    ap.add_argument("--quick", action="store_true",
                    help="4 images per set, 2 pairs each (CI)")
    ap.add_argument("--jobs", type=int, default=1,
                    help="parallel HOME subprocesses")
    ap.add_argument("--timeout", type=float, default=60.0,
                    help="seconds per HOME call")
    ap.add_argument("--worst", type=int, default=5,
                    help="list the N worst pairs of the first non-identity method")
    ap.add_argument("--cache", default=os.environ.get(
        "HOME_EVAL_CACHE", str(REPO / "build/eval-cache")))
    args = ap.parse_args()
    if args.quick:
        args.images = args.images or 4
        args.pairs = 2
    args.linear = LINEAR[:args.images]
    args.normal = NORMAL[:args.images]
    for s in args.sets:
        if s not in ("linear", "normal"):
            sys.exit(f"unknown set {s!r}")

    if "home" in args.methods and not os.access(args.home, os.X_OK):
        sys.exit(f"HOME CLI not found/executable: {args.home}\n"
                 "build it (make) or pass --home PATH, or use "
                 "--methods identity,orb")
    cache = Path(args.cache).resolve()
    paths = ensure_images(cache, set(args.linear) | set(args.normal))
    for s, lst in (("linear", args.linear), ("normal", args.normal)):
        if s in args.sets:
            missing = [n for n in lst if n not in paths]
            print(f"{s} images: {', '.join(n for n in lst if n in paths)}"
                  + (f"  (missing, skipped: {', '.join(missing)})" if missing else ""))
    print(f"pairs per setting: {args.pairs}; p: {args.p}; alpha: {args.alpha}; "
          f"methods: {','.join(args.methods)}; home: {args.home} {args.home_args}")

    methods = get_methods(args.methods)
    pairs = build_pairs(args, cache, paths)
    if not pairs:
        sys.exit("no pairs generated")
    evaluate(pairs, methods, args)
    summarise(pairs, methods, "linear", "p", "p")
    summarise(pairs, methods, "normal", "alpha", "alpha")
    print("\nerr = mean corner distance (px); failures scored at identity error; "
          "mean_ok = mean over non-failed pairs; ms_med = median time per pair"
          + (" (HOME: CLI-reported total, else subprocess wall)" if "home" in methods else ""))
    out = dump(pairs, methods, cache)
    focus = next((m for m in ("home", "orb", "akaze") if m in methods), None)
    if focus:
        print_worst(pairs, focus, args.worst)
    print(f"\nper-pair results: {out}/pairs_eval.json, pairs_eval.csv")


if __name__ == "__main__":
    main()
