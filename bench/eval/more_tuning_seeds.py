#!/usr/bin/env python3
"""More seeds of the tuning generator's hard scenes, for diagnosis and tuning only.

The tuning set has one to seven sequences per hard scene; a rule that fits them may still fail on
other seeds. This renders consecutive-frame sequences of scenes.py's generator A (tuning) for
seeds beyond the catalogue's (v20 on by default; the catalogue uses v0-v6), under the trust
evaluation's conditions, runs home-register on every pair and prints failures, silent errors
(ok but > 2 px off) and ok answers beyond 3 predicted errors, per condition and per path
(refine_status and model) of the ok answers. Generator B (the sealed test set's) is never
used. docs/trust.md, sessions 34 and 35.

    python3 bench/eval/more_tuning_seeds.py --home build/bin/home-register \\
        [--kinds few_edges] [--conditions lens_shading,day] [--seeds 20:80] [--config video] \\
        [--json OUT.json]
"""
import argparse
import collections
import json
import os
import sys
import types
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import trust               # noqa: E402
import trust_catalogue     # noqa: E402
import trust_data          # noqa: E402
from common import parallel_map  # noqa: E402

CACHE = Path(os.environ.get("HOME_EVAL_CACHE", HERE.parents[1] / "build" / "eval-cache"))


def silent(o):
    """An ok answer more than 2 px off."""
    return o["err"] > trust.SILENT_PX


def beyond_3_sigma(o):
    """An ok answer off by more than 3 predicted errors."""
    return o["err"] > 3 * o.get("sigma_px", 0.0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--home", default=str(HERE.parents[1] / "build/bin/home-register"))
    ap.add_argument("--kinds", default="few_edges", help="scenes.py kinds, comma-separated")
    ap.add_argument("--conditions", default="lens_shading,day")
    ap.add_argument("--seeds", default="20:80", help="first:last (exclusive), generator A seeds")
    ap.add_argument("--config", default="video", choices=sorted(trust.CONFIGS))
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--json", default=None, help="every result goes here")
    args = ap.parse_args()
    first, last = map(int, args.seeds.split(":"))
    if first < 7:
        sys.exit("seeds below v7 are the tuning catalogue's own sequences")
    kinds = args.kinds.split(",")
    # the catalogue's module, with these scenes and conditions in place of its own
    cat = types.SimpleNamespace(**{k: getattr(trust_catalogue, k) for k in dir(trust_catalogue)
                                   if not k.startswith("__")})
    cat.video_scenes = lambda which: [
        trust_catalogue.Item(f"more {k} v{i}", scene=(k, "A", f"v{i}"))
        for k in kinds for i in range(first, last)]
    cat.VIDEO_CONDITIONS = args.conditions.split(",")
    lib = trust_data.TrustLibrary(CACHE)
    recs = trust_data.build_video(lib, "tuning", False, CACHE / "more-tuning-seeds", cat, 60,
                                  args.jobs)
    outs = parallel_map(lambda r: trust.run_home(args.home, trust.CONFIGS[args.config], r), recs,
                        args.jobs)
    groups = collections.defaultdict(list)
    for r, o in zip(recs, outs):
        r["result"] = o
        groups[r["group"]].append(r)
    print(f"{args.home} {' '.join(trust.CONFIGS[args.config])}, generator A seeds "
          f"v{first}-v{last - 1} of {args.kinds}")
    print("| condition | pairs | failures | silent > 2 px | > 3 sigma | mean ok px |")
    print("|---|---|---|---|---|---|")
    for cond, rs in groups.items():
        ok = [r["result"] for r in rs if r["result"].get("ok")]
        mean = sum(o["err"] for o in ok) / len(ok) if ok else float("nan")
        print(f"| {cond} | {len(rs)} | {100 - 100 * len(ok) / len(rs):.1f} % | "
              f"{sum(map(silent, ok))} | {sum(map(beyond_3_sigma, ok))} | {mean:.3f} |")
    # which path the ok answers took: a silent rate that one path concentrates shows here
    paths = collections.defaultdict(lambda: [0, 0, 0])
    for r in recs:
        o = r["result"]
        if o.get("ok"):
            row = paths[(r["group"], o.get("refine_status"), o.get("model"))]
            row[0] += 1
            row[1] += silent(o)
            row[2] += beyond_3_sigma(o)
    print()
    print("| condition | refine_status | model | ok | silent > 2 px | > 3 sigma |")
    print("|---|---|---|---|---|---|")
    for (cond, status, model), (n, n_silent, n_beyond) in sorted(paths.items(), key=str):
        print(f"| {cond} | {status} | {model} | {n} | {n_silent} | {n_beyond} |")
    print()
    for r in recs:
        o = r["result"]
        if o.get("ok") and silent(o):
            print(f"silent: {r['image']} {r['group']} #{r['idx']}: {o['err']:.2f} px at a "
                  f"predicted {o['sigma_px']:.3f} ({o.get('refine_status')}, {o.get('model')})")
    if args.json:
        Path(args.json).write_text(json.dumps(recs))


if __name__ == "__main__":
    main()
