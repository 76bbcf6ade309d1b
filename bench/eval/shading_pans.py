#!/usr/bin/env python3
"""Lens shading under the stabiliser: pans and a tripod shot seen through a vignetting lens.

A falloff towards the corners, fixed to the sensor, stands still whatever the camera does; on a
plain background it looks like a background that does not move. This renders, from the tuning
set's material only (opencv-doc's home.jpg through scenes.fog, scenes.py generator A, and the
tuning set's raw static fog clip when `make eval-trust` has built it):

  pans     a still camera for 30 frames, then a pan of (1.0, 0.2) or (-0.6, 0.3) px a frame
           for 120 frames, falloff 0, 15 or 30 % at the corners, noise sigma 2
  tripod   the raw fog clip (a still camera, textured objects moving over fog) through a
           15 or 30 % falloff

and runs each home-stab given (`--stab A --stab B ...`) on every clip: the raw camera path at
the last frame (px; the truth: the scene's shift over the pan's 120 frames, the tripod's 0)
and the frames' motion statuses. docs/trust.md, session 25.

    python3 bench/eval/shading_pans.py --stab build/bin/home-stab [--stab OTHER] [--out DIR]
"""
import argparse
import csv
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import scenes      # noqa: E402
import trust_data  # noqa: E402

W, H = 640, 360
STILL, MOVING = 30, 120
CACHE = Path(os.environ.get("HOME_EVAL_CACHE", HERE.parents[1] / "build" / "eval-cache"))


def falloff_map(vig):
    yy, xx = np.mgrid[0:H, 0:W].astype(np.float64)
    r2 = ((xx - (W - 1) / 2) ** 2 + (yy - (H - 1) / 2) ** 2) / (((W - 1) / 2) ** 2 + ((H - 1) / 2) ** 2)
    return 1.0 - vig * r2


def sources():
    home = CACHE / "photos" / "opencv-doc" / "home.jpg"
    if home.exists():
        img = cv2.imread(str(home), cv2.IMREAD_GRAYSCALE).astype(np.float32)
        img = cv2.resize(img, (1440, int(img.shape[0] * 1440 / img.shape[1])))
        yield "home_fog", scenes.fog(img, np.random.default_rng(5))
    yield "fog_horizon_A", scenes.render("fog_horizon", "A", "pan1", 1440, 600)
    yield "few_edges_A", scenes.render("few_edges", "A", "pan3", 1440, 600)


def pan(src, vig, vx, vy):
    rng = np.random.default_rng(0)
    shade = falloff_map(vig)
    frames = []
    for i in range(STILL + MOVING):
        t = max(0, i - STILL)
        m = np.float32([[1, 0, -(40.0 + vx * t)], [0, 1, -((src.shape[0] - H) / 2 + vy * t)]])
        f = cv2.warpAffine(src, m, (W, H), flags=cv2.INTER_LINEAR) * shade
        frames.append(np.clip(np.rint(f + rng.normal(0, 2.0, f.shape)), 0, 255).astype(np.uint8))
    return frames


def build(out):
    clips = []
    for name, src in sources():
        for vig in (0.0, 0.15, 0.3):
            for vx, vy in ((1.0, 0.2), (-0.6, 0.3)):
                path = out / f"{name}_falloff{vig:.2f}_pan{vx:+.1f}{vy:+.1f}.y4m"
                if not path.exists():
                    trust_data.write_y4m(path, pan(src, vig, vx, vy))
                clips.append((path, f"{-MOVING * vx:.0f}, {-MOVING * vy:.0f}"))
    raw = CACHE / "trust" / "tuning" / "static" / "scene_fog_horizon_A_static1_raw_n300" / "clip.y4m"
    if raw.exists():
        frames = trust_data.read_y4m_luma(raw)
        for vig in (0.15, 0.3):
            path = out / f"raw_fog_static_falloff{vig:.2f}.y4m"
            if not path.exists():
                shade = falloff_map(vig)
                trust_data.write_y4m(path, [np.clip(np.rint(f * shade), 0, 255).astype(np.uint8)
                                            for f in frames])
            clips.append((path, "0, 0"))
    return clips


def run(stab, clip):
    with tempfile.TemporaryDirectory() as tmp:
        table = Path(tmp) / "path.csv"
        subprocess.run([stab, "--quiet", "--csv", str(table), str(clip), "-"], check=True,
                       stdout=subprocess.DEVNULL)
        rows = list(csv.DictReader(table.open()))
    statuses = {}
    for r in rows[1:]:
        statuses[r["status"]] = statuses.get(r["status"], 0) + 1
    last = rows[-1]
    return (f"{float(last['raw_tx']):.1f}, {float(last['raw_ty']):.1f} "
            f"({', '.join(f'{k} {v}' for k, v in sorted(statuses.items()))})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--stab", action="append", required=True, help="a home-stab binary")
    ap.add_argument("--out", default=str(CACHE / "shading-pans"), help="clips go here")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print("| clip | truth px (the scene's shift at the end) | " + " | ".join(args.stab) + " |")
    print("|---|---|" + "---|" * len(args.stab))
    for clip, truth in build(out):
        print(f"| {clip.stem} | {truth} | " + " | ".join(run(s, clip) for s in args.stab) + " |")


if __name__ == "__main__":
    main()
