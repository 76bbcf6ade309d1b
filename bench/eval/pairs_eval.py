"""Synthetic image pairs, exactly as in the HOME paper.

  * grey photograph scaled to cover 854x480 and centre-cropped;
  * ground truth: the four corners of the 854x480 frame each shifted uniformly
    in [-p, p] per coordinate, the frame warped by that homography (bilinear);
  * the central 640x360 of original (A) and warped (B) kept, so
    H_crop = T^-1 H T with T the translation by the crop offset (107, 60);
  * texture decay I' = I + alpha (128 - I) on both crops (the normal set);
  * Gaussian noise sigma 2.5 added to both, rounded and clipped to uint8.
The linear set sweeps p in {10..60} (alpha = 0); the normal set sweeps alpha
at p = 20.  A pair's geometry and noise depend only on (image, p, index), so
an alpha sweep varies texture alone and any subset reproduces the same pairs.

run.py evaluates the methods on these pairs.  Run alone, this file only
writes them, <cache>/pairs/<set>/<image>_p<p>[_a<alpha>]_i<n>/{A,B}.pgm and
gt.json (the true H, row-major), for other tools (bench/refine):
  python3 bench/eval/pairs_eval.py [--quick] [--sets linear,normal] [--cache DIR]
"""
import argparse
import json
import os
import sys
from pathlib import Path

import cv2
import numpy as np

from common import (CROP_H, CROP_W, FULL_H, FULL_W, NOISE_SIGMA, corner_error,
                    cover_resize, rng_for, to_u8, write_pgm)

P_LIST = [10, 20, 30, 40, 50, 60]
ALPHAS = [0.0, 0.4, 0.6, 0.8, 0.9, 0.95]
DECAY_P = 20
PAIRS_PER_IMAGE = 5
OX, OY = (FULL_W - CROP_W) // 2, (FULL_H - CROP_H) // 2
FULL_PLAN = {"p": P_LIST, "alpha": ALPHAS, "pairs": PAIRS_PER_IMAGE}


def warp_full(full, key, p):
    """The protocol's geometry: the full frame warped by moving its corners up to p px (seeded
    by key), and the true homography between the central crops (not normalised)."""
    src = np.float32([[0, 0], [FULL_W - 1, 0], [0, FULL_H - 1], [FULL_W - 1, FULL_H - 1]])
    dst = src + rng_for(key).uniform(-p, p, (4, 2)).astype(np.float32)
    Hf = cv2.getPerspectiveTransform(src, dst)
    warped = cv2.warpPerspective(full, Hf, (FULL_W, FULL_H), flags=cv2.INTER_LINEAR,
                                 borderMode=cv2.BORDER_REFLECT)
    T = np.array([[1, 0, OX], [0, 1, OY], [0, 0, 1]], float)
    return warped, np.linalg.inv(T) @ Hf @ T


def make_pair(full, name, p, idx, alpha=0.0):
    """(A, B, H_true) for one pair of the protocol."""
    key = f"{name}|p{p}|{idx}"
    warped, Hc = warp_full(full, key, p)
    noise = rng_for(key + "|noise")
    out = []
    for im in (full, warped):
        im = im[OY:OY + CROP_H, OX:OX + CROP_W]
        im = im + alpha * (128.0 - im)
        out.append(to_u8(im + noise.normal(0, NOISE_SIGMA, im.shape)))
    return out[0], out[1], Hc / Hc[2, 2]


def build(lib, sets, plan, workdir):
    """Synthesise the pairs.  sets: {"linear": [Photo], "normal": [Photo]};
    plan: {"p": [...], "alpha": [...], "pairs": n}.  Returns records holding
    the images (imgA, imgB), their PGM paths and the truth."""
    records = []
    for group, photos in sets.items():
        for photo in photos:
            full = cover_resize(lib.grey(photo), FULL_W, FULL_H)
            if group == "linear":
                settings = [(p, 0.0) for p in plan["p"]]
            else:
                settings = [(DECAY_P, a) for a in plan["alpha"]]
            for p, alpha in settings:
                for idx in range(plan["pairs"]):
                    A, B, Ht = make_pair(full, photo.name, p, idx, alpha)
                    tag = f"{photo.name}_p{p}" + (f"_a{alpha:g}" if group == "normal" else "") \
                        + f"_i{idx}"
                    d = workdir / group / tag
                    d.mkdir(parents=True, exist_ok=True)
                    write_pgm(d / "A.pgm", A)
                    write_pgm(d / "B.pgm", B)
                    (d / "gt.json").write_text(json.dumps({"H": Ht.ravel().tolist()}))
                    records.append({
                        "suite": "pairs", "group": group, "image": photo.name,
                        "p": p, "alpha": alpha, "idx": idx,
                        "A": str(d / "A.pgm"), "B": str(d / "B.pgm"),
                        "imgA": A, "imgB": B, "H_true": Ht,
                        "err_identity": corner_error(np.eye(3), Ht)})
    return records


def main():
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import catalogue
    from data import Library
    repo = Path(__file__).resolve().parents[2]
    ap = argparse.ArgumentParser(description="write the synthetic pairs (no evaluation)")
    ap.add_argument("--cache", default=os.environ.get("HOME_EVAL_CACHE",
                                                      str(repo / "build/eval-cache")))
    ap.add_argument("--sets", default="linear,normal")
    ap.add_argument("--quick", action="store_true", help="the CI subset of run.py --quick")
    ap.add_argument("--methods", help="ignored: kept for older callers; run.py evaluates")
    args = ap.parse_args()
    n = catalogue.QUICK_IMAGES if args.quick else None
    sets = {g: {"linear": catalogue.LINEAR, "normal": catalogue.NORMAL}[g][:n]
            for g in args.sets.split(",")}
    plan = catalogue.QUICK_PLAN if args.quick else FULL_PLAN
    lib = Library(args.cache)
    lib.fetch([p for ps in sets.values() for p in ps])
    recs = build(lib, sets, plan, Path(args.cache) / "pairs")
    print(f"{len(recs)} pairs in {Path(args.cache) / 'pairs'}")


if __name__ == "__main__":
    main()
