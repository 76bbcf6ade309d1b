#!/usr/bin/env python3
"""What the faint scenes determine: the Cramér-Rao bound of the corner error, and OpenCV's ECC.

Fog horizons, dim gradients and smooth blobs fail every frame of the trust evaluation. Two
measurements say whether they could be answered (docs/trust.md, session 39):
  1. the Cramér-Rao bound of the RMS corner error of a translation, a rigid motion and a
     similarity, from the noise-free render's gradients (scenes.py, generator A only) with
     Gaussian noise of --noise in both frames: no unbiased estimator does better;
  2. with --pairs (more_tuning_seeds.py's --json output), OpenCV's findTransformECC from the
     identity on every --step-th pair, per motion model: the corner error a dense method reaches.

    python3 bench/eval/faint_scenes_bound.py [--seeds 20:26] [--noise 2.5] [--pairs OUT.json]
"""
import argparse
import collections
import json
import sys
from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import scenes                      # noqa: E402
from common import corner_error    # noqa: E402

KINDS = ["fog_horizon", "dim_gradient", "textureless", "few_edges"]


def crb_corner_px(img, noise):
    """Cramér-Rao bound of the RMS corner error per model (T, E, S), parameters about the
    centre, both frames' noise in the residual."""
    gx = cv2.Sobel(img, cv2.CV_64F, 1, 0, ksize=3) / 8.0
    gy = cv2.Sobel(img, cv2.CV_64F, 0, 1, ksize=3) / 8.0
    h, w = img.shape
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    x -= w / 2.0
    y -= h / 2.0
    rot, scale = -y * gx + x * gy, x * gx + y * gy
    models = {"T": [gx, gy], "E": [gx, gy, rot], "S": [gx, gy, rot, scale]}
    corners = [(-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)]
    out = {}
    for name, cols in models.items():
        jac = np.stack([c.ravel() for c in cols], 1)
        cov = np.linalg.inv(jac.T @ jac / (2.0 * noise ** 2))
        total = 0.0
        for cx, cy in corners:
            d = np.array([[1, 0, -cy, cx], [0, 1, cx, cy]], float)[:, :len(cols)]
            total += np.trace(d @ cov @ d.T)
        out[name] = float(np.sqrt(total / 4.0))
    return out


def ecc_error(rec, motion):
    """Corner error of findTransformECC from the identity (B(W x) = A(x): W maps A to B)."""
    a = cv2.imread(rec["A"], cv2.IMREAD_GRAYSCALE).astype(np.float32)
    b = cv2.imread(rec["B"], cv2.IMREAD_GRAYSCALE).astype(np.float32)
    homography = motion == cv2.MOTION_HOMOGRAPHY
    warp = np.eye(3, dtype=np.float32) if homography else np.eye(2, 3, dtype=np.float32)
    try:
        _, warp = cv2.findTransformECC(a, b, warp, motion, (cv2.TERM_CRITERIA_EPS |
                                       cv2.TERM_CRITERIA_COUNT, 300, 1e-6), None, 5)
    except cv2.error:
        return float("nan")
    h = np.eye(3)
    h[:warp.shape[0]] = warp
    return corner_error(h, np.array(rec["H_true"]).reshape(3, 3))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="20:26", help="first:last (exclusive), generator A")
    ap.add_argument("--noise", type=float, default=2.5, help="grey levels in each frame")
    ap.add_argument("--pairs", default=None, help="more_tuning_seeds.py --json output")
    ap.add_argument("--step", type=int, default=12, help="ECC on every step-th pair")
    args = ap.parse_args()
    first, last = map(int, args.seeds.split(":"))
    if first < 7:
        sys.exit("seeds below v7 are the tuning catalogue's own sequences")
    print(f"Cramér-Rao bound of the RMS corner error, px (640x360, noise {args.noise}), "
          f"generator A seeds v{first}-v{last - 1}: min-max over the seeds")
    print("| kind | translation | rigid | similarity |\n|---|---|---|---|")
    for kind in KINDS:
        rows = [crb_corner_px(scenes.render(kind, "A", f"v{v}", 640, 360).astype(np.float64),
                              args.noise) for v in range(first, last)]
        cells = [f"{min(r[m] for r in rows):.3f}-{max(r[m] for r in rows):.3f}" for m in "TES"]
        print(f"| {kind} | " + " | ".join(cells) + " |")
    if not args.pairs:
        return
    models = {"translation": cv2.MOTION_TRANSLATION, "rigid": cv2.MOTION_EUCLIDEAN,
              "affine": cv2.MOTION_AFFINE, "homography": cv2.MOTION_HOMOGRAPHY}
    groups = collections.defaultdict(list)
    for rec in json.loads(Path(args.pairs).read_text())[::args.step]:
        kind = rec["image"].split("_A_")[0].replace("scene_", "")
        groups[(kind, rec["group"])].append([ecc_error(rec, m) for m in models.values()])
    print(f"\nOpenCV ECC from the identity, every {args.step}th pair: median corner error px "
          "(share under 1 px)")
    print("| kind | condition | pairs | " + " | ".join(models) + " |")
    print("|---|---|---|" + "---|" * len(models))
    for (kind, cond), rows in groups.items():
        errs = np.array(rows)
        cells = [f"{np.nanmedian(errs[:, i]):.2f} ({np.mean(errs[:, i] < 1.0):.0%})"
                 for i in range(len(models))]
        print(f"| {kind} | {cond} | {len(rows)} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
