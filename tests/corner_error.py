#!/usr/bin/env python3
"""Print the mean corner error of home-register's H against a known H: corner_error.py TRUTH RESULT"""
import json, sys

def apply(h, x, y):
    w = h[6] * x + h[7] * y + h[8]
    return (h[0] * x + h[1] * y + h[2]) / w, (h[3] * x + h[4] * y + h[5]) / w

truth = json.load(open(sys.argv[1]))
res = json.loads(open(sys.argv[2]).read().strip().splitlines()[-1])
w, h = truth.get("width", 640), truth.get("height", 360)
if not res.get("ok"):
    print("registration failed (ok:false)"); sys.exit(1)
err = 0.0
for x, y in ((0, 0), (w - 1, 0), (0, h - 1), (w - 1, h - 1)):
    ax, ay = apply(res["H"], x, y); bx, by = apply(truth["H"], x, y)
    err += ((ax - bx) ** 2 + (ay - by) ** 2) ** 0.5 / 4
print("mean corner error against the true H: %.3f px (%d inliers of %d matches)" % (err, res["inliers"], res["matches"]))
