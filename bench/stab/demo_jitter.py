#!/usr/bin/env python3
"""Residual jitter of a home-stab run against a home-stab-clip ground truth, standard library only
(so `make demo` needs no numpy): the camera the output shows is warp^-1 after the true camera;
its jitter is the px RMS of what a centred Gaussian of sigma 4 frames leaves (tx, ty, rotation
x half diagonal; 6 frames trimmed at each end), as in bench/stab/compare.py.
Usage: demo_jitter.py TRUTH.csv PATH.csv WIDTH HEIGHT"""
import csv
import math
import sys


def affine(rows, keys):
    return [[float(r[k]) for k in keys] for r in rows]


def compose(a, b):
    """a after b, both [m00, m01, m02, m10, m11, m12]"""
    return [a[0] * b[0] + a[1] * b[3], a[0] * b[1] + a[1] * b[4], a[0] * b[2] + a[1] * b[5] + a[2],
            a[3] * b[0] + a[4] * b[3], a[3] * b[1] + a[4] * b[4], a[3] * b[2] + a[4] * b[5] + a[5]]


def invert(m):
    det = m[0] * m[4] - m[1] * m[3]
    i = [m[4] / det, -m[1] / det, 0, -m[3] / det, m[0] / det, 0]
    i[2] = -(i[0] * m[2] + i[1] * m[5])
    i[5] = -(i[3] * m[2] + i[4] * m[5])
    return i


def components(m, w, h):
    cx, cy = 0.5 * (w - 1), 0.5 * (h - 1)
    half_diag = 0.5 * math.hypot(w, h)
    return [m[0] * cx + m[1] * cy + m[2] - cx, m[3] * cx + m[4] * cy + m[5] - cy,
            math.atan2(m[3], m[0]) * half_diag]


def jitter(path, sigma=4.0, trim=6):
    n, r = len(path), int(3 * sigma)
    total, count = 0.0, 0
    for t in range(trim, n - trim):
        for c in range(3):
            acc = wsum = 0.0
            for k in range(-r, r + 1):
                wt = math.exp(-0.5 * (k / sigma) ** 2)
                acc += wt * path[min(max(t + k, 0), n - 1)][c]
                wsum += wt
            total += (path[t][c] - acc / wsum) ** 2
            count += 1
    return math.sqrt(total / count)


def main():
    truth = list(csv.DictReader(open(sys.argv[1])))
    out = list(csv.DictReader(open(sys.argv[2])))
    w, h = int(sys.argv[3]), int(sys.argv[4])
    g = affine(truth, ["g00", "g01", "g02", "g10", "g11", "g12"])
    m = affine(out, ["w00", "w01", "w02", "w10", "w11", "w12"])
    n = min(len(g), len(m))
    shown = [components(compose(invert(m[t]), g[t]), w, h) for t in range(n)]
    raw = [components(g[t], w, h) for t in range(n)]
    held = sum(r["status"] in ("failed", "implausible") for r in out)
    print("residual jitter %.3f px RMS (input %.3f px), %d of %d frames held" %
          (jitter(shown), jitter(raw), held, n))


if __name__ == "__main__":
    main()
