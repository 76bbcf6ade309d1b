#!/usr/bin/env python3
"""HOME, HOME + refinement, ORB and ORB + the same refinement, side by side, on the synthetic
pairs of bench/eval/pairs_eval.py (the paper's protocol; pairs are read from its cache, and
built by it first when missing).

  HOME          home-register --no-refine
  HOME+refine   home-register (refinement on: the product, with its failure rule)
  ORB           OpenCV ORB(2000) + ratio 0.75 + findHomography(RANSAC), as in pairs_eval.py
  ORB+refine    home-refine-pair started from ORB's H (ORB failures stay failures)

Error = mean distance of the four corners under the estimated and the true H; a failure is
scored with the identity's error. Per group: mean, median, failures, pairs the refinement made
worse by more than 0.5 px, and how often it was accepted.

usage: python3 bench/refine/refine_eval.py [--build build] [--sets linear,normal] [--quick]
       [--jobs 2] [--out FILE.json]
"""
import argparse
import concurrent.futures
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
CORNERS = np.array([[0, 0], [639, 0], [0, 359], [639, 359]], float)


def project(H, pts):
    q = np.c_[pts, np.ones(len(pts))] @ np.asarray(H, float).reshape(3, 3).T
    return q[:, :2] / q[:, 2:3]


def corner_error(H, H_true):
    with np.errstate(all="ignore"):
        d = np.linalg.norm(project(H, CORNERS) - project(H_true, CORNERS), axis=1).mean()
    return float(d) if np.isfinite(d) else 1e9


def run_json(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}: {r.stderr[-300:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def orb_h(a_path, b_path):
    import cv2
    a = cv2.imread(str(a_path), cv2.IMREAD_GRAYSCALE)
    b = cv2.imread(str(b_path), cv2.IMREAD_GRAYSCALE)
    det = cv2.ORB_create(2000)
    ka, da = det.detectAndCompute(a, None)
    kb, db = det.detectAndCompute(b, None)
    good = []
    if da is not None and db is not None and len(da) >= 2 and len(db) >= 2:
        for m in cv2.BFMatcher(cv2.NORM_HAMMING).knnMatch(da, db, k=2):
            if len(m) == 2 and m[0].distance < 0.75 * m[1].distance:
                good.append(m[0])
    if len(good) < 4:
        return None
    src = np.float32([ka[m.queryIdx].pt for m in good])
    dst = np.float32([kb[m.trainIdx].pt for m in good])
    H, mask = cv2.findHomography(src, dst, cv2.RANSAC)
    if H is None or int(mask.sum()) < 20 or np.linalg.det(H[:2, :2] / H[2, 2]) <= 0:
        return None
    return (H / H[2, 2]).ravel()


def evaluate(pair, args):
    d = Path(pair)
    truth = np.asarray(json.load(open(d / "gt.json"))["H"], float)
    ident = corner_error(np.eye(3).ravel(), truth)
    reg = str(REPO / args.build / "bin/home-register")
    ref = str(REPO / args.build / "bin/home-refine-pair")
    out = {"pair": d.name, "set": d.parent.name, "identity": ident}
    home = run_json([reg, "--no-refine", str(d / "A.pgm"), str(d / "B.pgm")])
    out["home"] = corner_error(home["H"], truth) if home["ok"] else ident
    both = run_json([reg, str(d / "A.pgm"), str(d / "B.pgm")])
    out["home+refine"] = corner_error(both["H"], truth) if both["ok"] else ident
    out["home_refined"] = bool(both.get("refined"))
    out["home_ok"], out["home+refine_ok"] = bool(home["ok"]), bool(both["ok"])
    out["refine_ms"] = both["ms"].get("refine", 0.0)
    h_orb = orb_h(d / "A.pgm", d / "B.pgm")
    if h_orb is None:
        out["orb"] = out["orb+refine"] = ident
        out["orb_refined"] = False
    else:
        out["orb"] = corner_error(h_orb, truth)
        r = run_json([ref, str(d / "A.pgm"), str(d / "B.pgm")] + ["%.12g" % v for v in h_orb])
        out["orb+refine"] = corner_error(r["H"], truth)
        out["orb_refined"] = bool(r["refined"])
    return out


def group_of(row):
    name = row["pair"]
    if row["set"] == "linear":
        return "linear p=" + name.split("_p")[-1].split("_")[0]
    return "normal a=" + name.split("_a")[-1].split("_")[0]


def summarise(rows):
    methods = ["home", "home+refine", "orb", "orb+refine"]
    groups = sorted({group_of(r) for r in rows}, key=lambda g: (g.split()[0], float(g.split("=")[1])))
    groups += ["linear (all)", "normal (all)", "normal a<=0.8"]
    print(f"{'group':<16} {'n':>3}  " + "  ".join(f"{m + ' mean/med':>22}" for m in methods)
          + "   worse>0.5px  accepted(home/orb)")
    for g in groups:
        if g == "linear (all)":
            sel = [r for r in rows if r["set"] == "linear"]
        elif g == "normal (all)":
            sel = [r for r in rows if r["set"] == "normal"]
        elif g == "normal a<=0.8":
            sel = [r for r in rows if r["set"] == "normal" and float(group_of(r).split("=")[1]) <= 0.8]
        else:
            sel = [r for r in rows if group_of(r) == g]
        if not sel:
            continue
        cells = []
        for m in methods:
            e = np.array([r[m] for r in sel])
            cells.append(f"{e.mean():10.3f} / {np.median(e):8.3f}")
        worse = sum(r["home+refine"] > r["home"] + 0.5 for r in sel)
        worse_orb = sum(r["orb+refine"] > r["orb"] + 0.5 for r in sel)
        acc_h = sum(r["home_refined"] for r in sel)
        acc_o = sum(r["orb_refined"] for r in sel)
        print(f"{g:<16} {len(sel):>3}  " + "  ".join(f"{c:>22}" for c in cells)
              + f"   {worse:>3} / {worse_orb:<3}    {acc_h:>3} / {acc_o:<3}")
    ms = np.array([r["refine_ms"] for r in rows])
    print(f"\nrefinement inside home-register (two snapshots + solve): median {np.median(ms):.2f} ms")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--sets", default="linear,normal")
    ap.add_argument("--quick", action="store_true", help="pairs 0 and 1 of the first 4 images")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--cache", default=os.environ.get("HOME_EVAL_CACHE", str(REPO / "build/eval-cache")))
    ap.add_argument("--out", default=None, help="per-pair results as JSON")
    args = ap.parse_args()
    sets = [s for s in args.sets.split(",") if s]
    root = Path(args.cache) / "pairs"
    if not all((root / s).is_dir() for s in sets):
        subprocess.run([sys.executable, str(REPO / "bench/eval/pairs_eval.py"), "--methods",
                        "identity", "--sets", ",".join(sets)] + (["--quick"] if args.quick else []),
                       check=True)
    pairs = sorted(str(p) for s in sets for p in (root / s).iterdir() if (p / "gt.json").exists())
    if args.quick:
        firsts = {}
        for p in pairs:
            img = Path(p).name.split("_p")[0]
            firsts.setdefault(Path(p).parent.name, [])
            if img not in firsts[Path(p).parent.name]:
                firsts[Path(p).parent.name].append(img)
        keep = {(s, i) for s, imgs in firsts.items() for i in imgs[:4]}
        pairs = [p for p in pairs if (Path(p).parent.name, Path(p).name.split("_p")[0]) in keep
                 and Path(p).name[-3:] in ("_i0", "_i1")]
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as ex:
        rows = list(ex.map(lambda p: evaluate(p, args), pairs))
    summarise(rows)
    worst = sorted(rows, key=lambda r: r["home"] - r["home+refine"])[:5]
    print("\nlargest changes for the worse (home -> home+refine):")
    for r in worst:
        print(f"  {r['pair']:<32} {r['home']:8.3f} -> {r['home+refine']:8.3f}  refined={r['home_refined']}")
    if args.out:
        json.dump(rows, open(args.out, "w"), indent=1)


if __name__ == "__main__":
    main()
