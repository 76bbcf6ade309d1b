#!/usr/bin/env python3
"""Draw the README's two pictures from the output of `make demo` (not part of `make test`).

    make demo && python3 docs/make_figures.py [DEMO_DIR [OUT_DIR]]

DEMO_DIR (default build/demo) must hold side_by_side.y4m (`home-stab --side-by-side`: original |
stabilised) and path.csv (`home-stab --csv`). Writes to OUT_DIR (default docs/img):
  demo_side_by_side.png  one frame, original | stabilised, and the mean of 15 consecutive frames
                         of each (a shaking camera blurs the mean; a steady one keeps it sharp)
  demo_path.png          the raw camera path and the smoothed one (tx, ty, rotation), per frame
Needs numpy, matplotlib and opencv-python (cv2)."""
import csv
import os
import sys

import cv2
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FRAME = 60          # the frame shown
MEAN_FRAMES = 15    # frames averaged for the second row
OUT_WIDTH = 800     # width of the side-by-side picture, px


def read_y4m_luma(path):
    """Luma planes of a 4:2:0 or mono Y4M file, as a list of HxW uint8 arrays."""
    with open(path, "rb") as f:
        header = f.readline().split()
        if header[0] != b"YUV4MPEG2":
            raise SystemExit(f"{path}: not Y4M")
        fields = {h[:1]: h[1:] for h in header[1:]}
        w, h = int(fields[b"W"]), int(fields[b"H"])
        mono = fields.get(b"C", b"420").startswith(b"mono")
        chroma = 0 if mono else 2 * (w // 2) * (h // 2)
        frames = []
        while True:
            line = f.readline()
            if not line:
                break
            y = f.read(w * h)
            f.read(chroma)
            if len(y) < w * h:
                break
            frames.append(np.frombuffer(y, np.uint8).reshape(h, w))
        return frames


def label(img, text):
    cv2.putText(img, text, (10, 28), cv2.FONT_HERSHEY_SIMPLEX, 0.8, 0, 4, cv2.LINE_AA)
    cv2.putText(img, text, (10, 28), cv2.FONT_HERSHEY_SIMPLEX, 0.8, 255, 2, cv2.LINE_AA)


def side_by_side(frames, out):
    h, w2 = frames[0].shape
    w = w2 // 2
    one = frames[FRAME].copy()
    lo = max(0, FRAME - MEAN_FRAMES // 2)
    mean = np.mean(np.stack(frames[lo:lo + MEAN_FRAMES]).astype(np.float32), axis=0)
    mean = np.clip(mean + 0.5, 0, 255).astype(np.uint8)
    rows = []
    for img, what in ((one, f"frame {FRAME}"), (mean, f"mean of frames {lo}-{lo + MEAN_FRAMES - 1}")):
        left, right = img[:, :w].copy(), img[:, w:].copy()
        label(left, f"input, {what}")
        label(right, f"stabilised, {what}")
        rows.append(np.hstack([left, np.full((h, 6), 255, np.uint8), right]))
    pic = np.vstack([rows[0], np.full((6, rows[0].shape[1]), 255, np.uint8), rows[1]])
    scale = OUT_WIDTH / pic.shape[1]
    pic = cv2.resize(pic, (OUT_WIDTH, round(pic.shape[0] * scale)), interpolation=cv2.INTER_AREA)
    cv2.imwrite(out, pic, [cv2.IMWRITE_PNG_COMPRESSION, 9])


def path_plot(csv_path, out):
    with open(csv_path) as f:
        rows = list(csv.DictReader(f))
    t = [int(r["frame"]) for r in rows]
    fig, axes = plt.subplots(3, 1, figsize=(8, 5.2), sharex=True, dpi=80)
    for ax, key, unit, k in ((axes[0], "tx", "px", 1), (axes[1], "ty", "px", 1),
                             (axes[2], "angle", "degrees", 180 / np.pi)):
        ax.plot(t, [k * float(r["raw_" + key]) for r in rows], color="tab:red", lw=1,
                label="raw (registered frame to frame, accumulated)")
        ax.plot(t, [k * float(r["smooth_" + key]) for r in rows], color="tab:blue", lw=1.8,
                label="smoothed (what the output shows)")
        ax.set_ylabel(f"{key}, {unit}")
        ax.grid(alpha=0.3)
    axes[0].legend(loc="best", fontsize=8)
    axes[0].set_title("make demo: home-stab --lookahead 10, camera path (home-stab --csv)",
                      fontsize=10)
    axes[2].set_xlabel("frame")
    fig.tight_layout()
    fig.savefig(out)
    plt.close(fig)


def main():
    demo = sys.argv[1] if len(sys.argv) > 1 else "build/demo"
    out = sys.argv[2] if len(sys.argv) > 2 else "docs/img"
    os.makedirs(out, exist_ok=True)
    side_by_side(read_y4m_luma(os.path.join(demo, "side_by_side.y4m")),
                 os.path.join(out, "demo_side_by_side.png"))
    path_plot(os.path.join(demo, "path.csv"), os.path.join(out, "demo_path.png"))
    for name in ("demo_side_by_side.png", "demo_path.png"):
        p = os.path.join(out, name)
        print(f"{p}: {os.path.getsize(p) // 1024} KB")


if __name__ == "__main__":
    main()
