#!/usr/bin/env python3
"""Can `ok` be trusted?  home-register on a tuning set and a sealed test set.

  python3 bench/eval/trust.py                  # full run: bench/eval/trust_results.md + PNGs
  python3 bench/eval/trust.py --quick          # CI subset: build/eval-cache/trust-quick/
  python3 bench/eval/trust.py --sets test --suites static --home build-x/bin/home-register

Three sets: tuning, test and sealed (static clips only, kept for a final check
after the test set's static clips were looked at; the full run includes it,
--quick leaves it out unless --sets names it).
Three suites, on the tuning and test sets (trust_catalogue.py says what is in them):
  pairs   the paper's still-pair protocol on photographs and rendered hard
          scenes, in groups a-g (few edges, fog / dim, low light, repeated
          patterns, line-rich p = 10..60, texture decay alpha = 0..0.95, textureless)
  video   consecutive frames of a hand-held camera (about 3 px a frame): day,
          low light, motion blur, 5x shake
  static  a static camera with moving objects, H.264 round trip: the truth is the
          identity for every pair; per pair error and the drift of the chained
          estimates over the clip, and home-stab's raw camera path on the same clip

Every pair is registered by `home-register A.pgm B.pgm` (defaults) and by
`home-register --video A.pgm B.pgm`, plus --extra-args.  The library's own "ok"
decides failure; optional JSON fields "sigma_px", "model" and "refine_status"
are reported where the binary gives them ("n/a" where it does not).

Generated data is cached under <cache>/trust/<set>/ (reruns skip generation);
the results go to <out>/trust_results.json.gz (compact, enough to redraw the report
with `trust_report.py <out>/trust_results.json.gz`) and <cache>/trust-runs/*.json
(every H).  Exit status: non-zero only when the harness itself breaks
(home-register crashing or printing no JSON on generated inputs, no pairs).
"""
import argparse
import csv
import gzip
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import trust_catalogue as catalogue                     # noqa: E402  (extends data.PACKAGES)
import trust_data                                       # noqa: E402
import trust_report                                     # noqa: E402
from common import CROP_H, CROP_W, corner_error, git_describe, parallel_map, usable  # noqa: E402

REPO = HERE.parents[1]
CONFIGS = {"defaults": [], "video": ["--video"]}
SILENT_PX = 2.0


def run_home(exe, args, rec, timeout=120):
    """One home-register run -> a result dict (never raises)."""
    cmd = [exe] + args + [rec["A"], rec["B"]]
    t0 = time.perf_counter()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"status": "error", "detail": "timeout"}
    except OSError as e:             # e.g. the binary replaced by a rebuild under us
        return {"status": "error", "detail": f"cannot run {exe}: {e}"}
    wall = (time.perf_counter() - t0) * 1e3
    if r.returncode != 0:
        return {"status": "error", "ms": wall,
                "detail": f"exit {r.returncode}: {r.stderr.strip()[-300:]}"}
    try:
        j = json.loads(r.stdout.strip().splitlines()[-1])
    except (ValueError, IndexError):
        return {"status": "error", "ms": wall, "detail": f"no JSON: {r.stdout[-300:]!r}"}
    H = np.asarray(j.get("H") or [np.nan] * 9, float).reshape(3, 3)
    ok = bool(j.get("ok")) and bool(usable(H))
    res = {"status": "ok" if ok else "fail", "ok": ok,
           "ms": (j.get("ms") or {}).get("total", wall), "inliers": j.get("inliers")}
    for k in ("sigma_px", "model", "refine_status", "refined", "failure"):
        if k in j:
            res[k] = j[k]
    if usable(H):
        H = H / H[2, 2]
        res["H"] = H.ravel().tolist()
        res["err"] = corner_error(H, np.array(rec["H_true"]).reshape(3, 3))
    return res


def evaluate(records, exe, extra, jobs):
    timing = {}
    for cfg, args in CONFIGS.items():
        t0 = time.perf_counter()
        outs = parallel_map(lambda rec: run_home(exe, args + extra, rec), records, jobs)
        for rec, res in zip(records, outs):
            rec.setdefault("results", {})[cfg] = res
        timing[cfg] = time.perf_counter() - t0
        errors = [r for r in outs if r["status"] == "error"]
        print(f"#   {cfg}: {len(records)} pairs in {timing[cfg]:.1f} s"
              + (f", {len(errors)} ERRORS e.g. {errors[0]['detail']}" if errors else ""),
              file=sys.stderr)
    return timing


# --------------------------------------------------------------------------
# Static clips: chained estimates and home-stab's path
# --------------------------------------------------------------------------
_C = np.array([(CROP_W - 1) / 2, (CROP_H - 1) / 2])
_CORNERS = np.array([[0, 0], [CROP_W - 1, 0], [0, CROP_H - 1], [CROP_W - 1, CROP_H - 1]], float)


def sim_corner_drift(tx, ty, angle, log_scale):
    """Mean corner displacement of home_stab's similarity about the centre."""
    s = np.exp(log_scale)
    R = s * np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
    moved = (_CORNERS - _C) @ R.T + _C + [tx, ty]
    return float(np.linalg.norm(moved - _CORNERS, axis=1).mean())


def chain_drift(recs, cfg):
    """Corner error of the product of the consecutive H's (ok answers only; a
    failed pair contributes the identity), after every frame."""
    acc, curve = np.eye(3), [0.0]
    for rec in sorted(recs, key=lambda r: r["idx"]):
        res = rec["results"][cfg]
        if res.get("ok") and "H" in res:
            acc = np.array(res["H"]).reshape(3, 3) @ acc
            acc /= acc[2, 2]
        curve.append(corner_error(acc, np.eye(3)))
    return curve


def run_stab(stab, clip):
    """home-stab on the clip; its raw camera path as corner drift per frame."""
    csv_path = Path(clip["y4m"]).with_name("stab.csv")
    t0 = time.perf_counter()
    r = subprocess.run([stab, "--quiet", "--csv", str(csv_path), clip["y4m"], "-"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                       timeout=600)
    wall = time.perf_counter() - t0
    if r.returncode != 0 or not csv_path.exists():
        return {"status": "error", "detail": f"exit {r.returncode}: {r.stderr[-300:]}"}
    rows = list(csv.DictReader(csv_path.open()))
    drift = [sim_corner_drift(float(x["raw_tx"]), float(x["raw_ty"]), float(x["raw_angle"]),
                              float(x["raw_log_scale"])) for x in rows]
    last = rows[-1]
    statuses = {}
    for x in rows[1:]:
        statuses[x["status"]] = statuses.get(x["status"], 0) + 1
    extra_cols = [c for c in rows[0] if c not in (
        "frame", "status", "inliers", "raw_tx", "raw_ty", "raw_angle", "raw_log_scale",
        "smooth_tx", "smooth_ty", "smooth_angle", "smooth_log_scale", "correction_used")
        and not c.startswith("w")]
    out = {"status": "ok", "frames": len(rows), "wall_s": wall, "statuses": statuses,
           "drift_curve": [round(v, 4) for v in drift],
           "final_tx": float(last["raw_tx"]), "final_ty": float(last["raw_ty"]),
           "final_angle_deg": float(np.degrees(float(last["raw_angle"]))),
           "max_drift_px": max(drift), "final_drift_px": drift[-1],
           "max_angle_deg": max(abs(np.degrees(float(x["raw_angle"]))) for x in rows)}
    out["extra_columns"] = extra_cols   # e.g. model and sigma_px per frame, when present
    if "model" in rows[0]:
        models = {}
        for x in rows[1:]:
            models[x["model"]] = models.get(x["model"], 0) + 1
        out["models"] = models
    return out


# --------------------------------------------------------------------------
def compact(records):
    """Per record, what the report needs (no H, no paths)."""
    keep = ("set", "suite", "group", "row", "image", "p", "alpha", "idx", "err_identity")
    rkeep = ("status", "ok", "err", "sigma_px", "model", "refine_status", "ms", "inliers")
    out = []
    for rec in records:
        r = {k: rec[k] for k in keep if k in rec}
        r["results"] = {}
        for cfg, res in rec["results"].items():
            x = {k: res[k] for k in rkeep if k in res}
            for k in ("err", "ms", "sigma_px"):
                if isinstance(x.get(k), float) and np.isfinite(x[k]):
                    x[k] = round(x[k], 5)
                elif isinstance(x.get(k), float):
                    x[k] = None
            r["results"][cfg] = x
        out.append(r)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--home", default=str(REPO / "build/bin/home-register"))
    ap.add_argument("--stab", default=None, help="home-stab (default: beside --home)")
    ap.add_argument("--extra-args", default="", help="more home-register options, one string")
    ap.add_argument("--sets", default=None,
                    help="comma-separated, from " + ",".join(catalogue.SETS) + " (default "
                    "all; --quick: tuning,test); the sealed set has static clips only")
    ap.add_argument("--suites", default="pairs,video,static")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="the CI subset")
    ap.add_argument("--cache", default=os.environ.get("HOME_EVAL_CACHE",
                                                      str(REPO / "build/eval-cache")))
    ap.add_argument("--out", default=None,
                    help="report directory (default bench/eval, or <cache>/trust-quick)")
    ap.add_argument("--label", default=None,
                    help="the binary's commit for the report (default: git describe of "
                         "the binary's directory)")
    ap.add_argument("--video-frames", type=int, default=None, help="default 60 (quick 6)")
    ap.add_argument("--static-frames", type=int, default=None, help="default 300 (quick 40)")
    args = ap.parse_args()

    if not os.access(args.home, os.X_OK):
        sys.exit(f"{args.home} is not an executable: build it (make) or pass --home")
    stab = args.stab or str(Path(args.home).resolve().parent / "home-stab")
    cv2.setNumThreads(1)
    cache = Path(args.cache).resolve()
    out = Path(args.out) if args.out else (cache / "trust-quick" if args.quick else HERE)
    out.mkdir(parents=True, exist_ok=True)
    if args.sets is None:
        args.sets = ",".join(s for s in catalogue.SETS
                             if not (args.quick and s in catalogue.STATIC_ONLY))
    sets = [s for s in args.sets.split(",") if s]
    suites = [s for s in args.suites.split(",") if s]
    bad = [s for s in sets if s not in catalogue.SETS] + \
        [s for s in suites if s not in ("pairs", "video", "static")]
    if bad:
        sys.exit(f"unknown sets/suites {bad}")
    extra = shlex.split(args.extra_args)
    vframes = args.video_frames or (catalogue.QUICK["video_frames"] if args.quick else 60)
    sframes = args.static_frames or (catalogue.QUICK["static_frames"] if args.quick else 300)

    lib = trust_data.TrustLibrary(cache)
    q = catalogue.QUICK if args.quick else {}
    photos = set()                   # only what this run uses: --quick fetches less
    for s in sets:
        if "pairs" in suites:
            photos |= {it.photo for its in catalogue.still_groups(s).values()
                       for it in its[:q.get("items_per_group")] if it.photo}
        if "video" in suites:
            photos |= {it.photo for it in catalogue.video_scenes(s)[:q.get("video_scenes")]
                       if it.photo}
        if "static" in suites:
            for bg, tex in catalogue.static_clips(s)[:q.get("static_clips")]:
                photos |= set(tex) | ({bg.photo} if bg.photo else set())
    lib.fetch(sorted(photos, key=lambda p: (p.source, p.file)))

    root = cache / "trust"
    t_start = time.perf_counter()
    load0 = os.getloadavg()[1]
    records, clips, timing = [], [], {}
    for s in sets:
        for suite in suites:
            if s in catalogue.STATIC_ONLY and suite != "static":
                continue                           # the sealed set has clips only
            t0 = time.perf_counter()
            if suite == "pairs":
                recs = trust_data.build_pairs(lib, s, args.quick, root, catalogue, args.jobs)
            elif suite == "video":
                recs = trust_data.build_video(lib, s, args.quick, root, catalogue, vframes,
                                              args.jobs)
            else:
                recs, cl = trust_data.build_static(lib, s, args.quick, root, catalogue,
                                                   sframes, args.jobs)
                clips += cl
            gen = time.perf_counter() - t0
            print(f"# {s} {suite}: {len(recs)} pairs (data {gen:.1f} s)", file=sys.stderr)
            timing[f"{s}/{suite}"] = {"data_s": gen, **evaluate(recs, args.home, extra,
                                                                 args.jobs)}
            records += recs
    for clip in clips:
        recs = [r for r in records if r["suite"] == "static" and r["set"] == clip["set"]
                and r["group"] == clip["name"]]
        clip["chain"] = {cfg: [round(v, 4) for v in chain_drift(recs, cfg)] for cfg in CONFIGS}
        clip["stab"] = run_stab(stab, clip) if os.access(stab, os.X_OK) else \
            {"status": "missing", "detail": f"{stab} not found"}
        if clip["stab"]["status"] == "error":
            print(f"# home-stab on {clip['y4m']}: {clip['stab']['detail']}", file=sys.stderr)
    wall = time.perf_counter() - t_start

    meta = {
        "quick": args.quick, "home": args.home, "stab": stab, "extra_args": extra,
        "configs": {c: " ".join(["home-register"] + a + extra) for c, a in CONFIGS.items()},
        "commit": args.label or git_describe(Path(args.home).resolve().parent),
        "opencv": cv2.__version__, "python": platform.python_version(),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores", "jobs": args.jobs,
        "packages": lib.versions, "wall_s": wall, "timing_s": timing,
        "load": [load0, os.getloadavg()[1]], "sets": sets, "suites": suites,
        "video_frames": vframes, "static_frames": sframes, "silent_px": SILENT_PX,
        "catalogue": trust_report.describe_catalogue(catalogue, sets, args.quick),
    }
    runs = cache / "trust-runs"
    runs.mkdir(parents=True, exist_ok=True)
    tag = "quick" if args.quick else "full"
    (runs / f"{tag}.json").write_text(json.dumps({"meta": meta, "records": records,
                                                  "clips": clips}))
    compact_clips = [{k: v for k, v in c.items() if k != "y4m"} for c in clips]
    results = {"meta": meta, "records": compact(records), "clips": compact_clips}
    (out / "trust_results.json.gz").write_bytes(gzip.compress(
        json.dumps(results, separators=(",", ":")).encode(), mtime=0))
    trust_report.write(out, results)
    print(f"report: {out / 'trust_results.md'} ({wall:.0f} s); every H: {runs / (tag + '.json')}")

    broken = [(r["A"], x.get("detail")) for r in records for x in r["results"].values()
              if x["status"] == "error"]
    if broken:
        sys.exit(f"{len(broken)} home-register runs ended in an error, e.g. {broken[0]}")
    if not records:
        sys.exit("no pairs were evaluated")
    stab_broken = [c for c in clips if c["stab"]["status"] == "error"]
    if stab_broken:
        sys.exit(f"home-stab failed on {stab_broken[0]['name']}: {stab_broken[0]['stab']}")


if __name__ == "__main__":
    main()
