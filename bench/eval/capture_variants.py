#!/usr/bin/env python3
"""Dim few-edges frames captured five ways: which step of the low-light capture misleads HOME.

The trust evaluation's consecutive frames of the few-edges scenes in low light are where most
ok answers beyond 3 predicted errors are (homographies whose perspective entries are 10-30
times the truth's: docs/trust.md, session 31). This renders the same worlds with the same
camera, gain and noise keys as `make eval-trust`'s low-light frames (trust_data's; 40 frames
instead of 60) and captures each frame five ways:

  evaluated  as the evaluation does: brightness 10-25 %, shot noise, read noise 1.5 DN,
             rounding to 8 bits, clipping at 0
  pedestal   the same with a 16 DN black level (nothing clipped)
  gauss      Gaussian noise of the same mean variance instead of shot and read noise
  bright4    four times as bright
  rounding   no noise at all: the rounding of the dim image alone

then registers every consecutive pair with home-register (defaults) and prints, per scene and
capture: ok answers, of them homographies, beyond 3 sigma and more than 1 px off (corner error
against the truth), and the mean error of the ok answers.

    python3 bench/eval/capture_variants.py --home build/bin/home-register [--out DIR]
"""
import argparse
import json
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import scenes  # noqa: E402
import video_eval  # noqa: E402
from common import CROP_H, CROP_W  # noqa: E402
from trust_data import HandheldCamera, rng_for, write_pgm  # noqa: E402

CAPTURES = ("evaluated", "pedestal", "gauss", "bright4", "rounding")
# (set, generator, seed): the test set's few-edges scenes with the most such answers, and two
# of the tuning set's
SCENES = [("test", "B", "v0"), ("test", "B", "v2"), ("test", "B", "v3"), ("test", "B", "v5"),
          ("tuning", "A", "v0"), ("tuning", "A", "v4")]
FRAMES = 40


def capture(img, gain, rng, how):
    """One 8-bit frame of img (float, 0..255 in daylight) at brightness gain."""
    e = np.clip(img, 0, 255) * min(gain * (4 if how == "bright4" else 1), 1.0) * (
        scenes.FULL_WELL_E / 255.0)
    dn_per_e = 255.0 / scenes.FULL_WELL_E
    if how == "rounding":
        dn = e * dn_per_e
    elif how == "gauss":
        sd = np.sqrt(np.mean(e) * dn_per_e ** 2 + scenes.READ_NOISE_DN ** 2)
        dn = e * dn_per_e + rng.normal(0, sd, img.shape)
    else:
        dn = rng.poisson(e).astype(np.float32) * dn_per_e + rng.normal(0, scenes.READ_NOISE_DN,
                                                                       img.shape)
    if how == "pedestal":
        dn = dn + 16.0
    return np.clip(np.rint(dn), 0, 255).astype(np.uint8)


def corner_error(h, truth):
    c = np.array([[0, 0], [CROP_W - 1, 0], [0, CROP_H - 1], [CROP_W - 1, CROP_H - 1]], float)

    def apply(m):
        q = np.c_[c, np.ones(4)] @ np.asarray(m, float).reshape(3, 3).T
        return q[:, :2] / q[:, 2:]
    return float(np.sqrt(((apply(h) - apply(truth)) ** 2).sum(1)).mean())


def run(home, out, which, variant, seed, how):
    ww, wh = round(CROP_W * video_eval.WORLD_SCALE), round(CROP_H * video_eval.WORLD_SCALE)
    world = scenes.render("few_edges", variant, seed, ww, wh)
    name = f"scene_few_edges_{variant}_{seed}"
    key = f"trust|{which}|video|{name}|low_light"
    cam = HandheldCamera(key, FRAMES, world.shape, 1.0)
    noise = rng_for(key + "|noise")
    gain = scenes.low_light_params(rng_for(key + "|gain"))["gain"]
    d = out / f"{name}_{how}"
    d.mkdir(parents=True, exist_ok=True)
    ms = []
    for t in range(FRAMES):
        write_pgm(d / f"{t:03d}.pgm", capture(video_eval.render(world, cam.M(t)), gain, noise, how))
        ms.append(cam.M(t))

    def register(t):
        r = subprocess.run([home, str(d / f"{t - 1:03d}.pgm"), str(d / f"{t:03d}.pgm")],
                           capture_output=True, text=True, check=True)
        truth = np.linalg.inv(ms[t]) @ ms[t - 1]
        return json.loads(r.stdout), (truth / truth[2, 2]).ravel()

    ok = []
    with ThreadPoolExecutor(2) as ex:
        for res, truth in ex.map(register, range(1, FRAMES)):
            if res["ok"]:
                ok.append((res["model"], corner_error(res["H"], truth), res["sigma_px"]))
    errors = [e for _, e, _ in ok]
    print(f"{name} ({which}) {how:9s} gain {gain:.2f}: ok {len(ok):2d}/{FRAMES - 1}, "
          f"homographies {sum(m == 'homography' for m, _, _ in ok):2d}, "
          f"beyond 3 sigma {sum(e > 3 * s for _, e, s in ok):2d}, "
          f"over 1 px {sum(e > 1 for e in errors):2d}, "
          f"mean {np.mean(errors) if errors else float('nan'):.2f} px", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--home", required=True, help="home-register")
    ap.add_argument("--out", help="where the frames go (default: a temporary directory)")
    ap.add_argument("--captures", default=",".join(CAPTURES))
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(args.out or tmp)
        for which, variant, seed in SCENES:
            for how in args.captures.split(","):
                run(args.home, out, which, variant, seed, how)


if __name__ == "__main__":
    main()
