#!/usr/bin/env python3
"""eis-libcamera on libcamera's virtual camera, checked (tests/checks/libcamera-virtual.sh).

  virtual_camera_check.py CLIP.y4m RAW.y4m OUT.y4m HS.y4m N_IMAGES REPEAT

CLIP: the rendered shaky frames the JPEGs were made of; RAW, OUT: eis-libcamera's frames as
captured and as stabilised; HS: home-stab on RAW's distinct frames (same options). The virtual
camera shows each image REPEAT times, so the captured frames come in runs of identical frames.
Checks, each printed and failing the exit status:
  frames      RAW and OUT hold N_IMAGES x REPEAT frames; RAW's runs are REPEAT long
  played      each distinct captured frame is its JPEG's image, in order: luma PSNR against
              CLIP's frame > 30 dB (gain and offset fitted: the JPEGs are full range), and
              above those against CLIP's frames before and after
  same bytes  every frame of OUT equals HS's frame of its run: eis-libcamera stabilised what it
              captured as home-stab does the same frames
  jitter      the residual jitter of OUT's distinct frames is below half the input's
Jitter: the frame-to-frame translation by phase correlation (Hann window, parabolic sub-pixel
peak) summed into a path; px RMS of what a centred Gaussian of sigma 4 frames leaves, 6 frames
trimmed at each end (bench/stab/compare.py's jitter, on a path measured from the frames alone).
Output pixels are zoomed by the crop (1.25x for 10 % margins), which magnifies their jitter.
Prints one JSON line of the numbers last.
"""
import json
import sys

import numpy as np


def read_y4m(path):
    d = open(path, 'rb').read()
    nl = d.index(b'\n')
    tags = {t[:1]: t[1:] for t in d[:nl].split()[1:]}
    w, h = int(tags[b'W']), int(tags[b'H'])
    size = w * h * 3 // 2
    frames, at = [], nl + 1
    while at < len(d):
        if d[at:at + 5] != b'FRAME':
            raise ValueError('%s: bad frame marker at byte %d' % (path, at))
        at = d.index(b'\n', at) + 1
        frames.append(d[at:at + size])
        at += size
    return frames, w, h


def luma(frame, w, h):
    return np.frombuffer(frame[:w * h], np.uint8).reshape(h, w).astype(np.float64)


def shift(a, b, win):
    """Translation of b against a (px), phase correlation with a parabolic sub-pixel peak."""
    fa, fb = np.fft.fft2((a - a.mean()) * win), np.fft.fft2((b - b.mean()) * win)
    r = fa.conj() * fb
    c = np.real(np.fft.ifft2(r / (np.abs(r) + 1e-9)))
    h, w = c.shape
    py, px = np.unravel_index(np.argmax(c), c.shape)

    def sub(m1, c0, p1):
        den = m1 - 2 * c0 + p1
        return 0.0 if den == 0 else 0.5 * (m1 - p1) / den
    dx = px + sub(c[py, (px - 1) % w], c[py, px], c[py, (px + 1) % w])
    dy = py + sub(c[(py - 1) % h, px], c[py, px], c[(py + 1) % h, px])
    return (dx - w if dx > w / 2 else dx), (dy - h if dy > h / 2 else dy)


def jitter(lumas, sigma=4.0, trim=6):
    h, w = lumas[0].shape
    win = np.outer(np.hanning(h), np.hanning(w))
    steps = [shift(lumas[i - 1], lumas[i], win) for i in range(1, len(lumas))]
    path = np.vstack([[0.0, 0.0], np.cumsum(np.array(steps), 0)])
    k = np.arange(-int(3 * sigma), int(3 * sigma) + 1)
    wts = np.exp(-0.5 * (k / sigma) ** 2)
    n = len(path)
    low = np.array([(wts[:, None] * path[np.clip(t + k, 0, n - 1)]).sum(0) / wts.sum() for t in range(n)])
    hf = (path - low)[trim:n - trim]
    return float(np.sqrt(np.mean(hf ** 2)))


def main():
    clip, w, h = read_y4m(sys.argv[1])
    raw, rw, rh = read_y4m(sys.argv[2])
    out, ow, oh = read_y4m(sys.argv[3])
    hs, _, _ = read_y4m(sys.argv[4])
    n_images, repeat = int(sys.argv[5]), int(sys.argv[6])
    failed = []

    def check(name, ok, detail):
        print('%s %s: %s' % ('ok  ' if ok else 'FAIL', name, detail))
        if not ok:
            failed.append(name)

    # runs of identical captured frames
    runs = []
    for i, f in enumerate(raw):
        if i and f == raw[i - 1]:
            runs[-1].append(i)
        else:
            runs.append([i])
    lengths = sorted(set(len(r) for r in runs))
    check('frames', len(raw) == n_images * repeat and len(out) == len(raw) and (rw, rh, ow, oh) == (w, h, w, h)
          and len(runs) == n_images and lengths == [repeat],
          '%d captured, %d stabilised of %d x %d; %d distinct, runs of %s' % (len(raw), len(out), n_images, repeat,
                                                                         len(runs), lengths))
    distinct = [luma(raw[r[0]], w, h) for r in runs]

    def psnr(d, c):
        # gain and offset fitted first: the JPEGs are full range, the rendered clip is not
        gain, offset = np.polyfit(c.ravel(), d.ravel(), 1)
        return 10 * np.log10(255.0 ** 2 / max(np.mean((d - (gain * c + offset)) ** 2), 1e-9))
    clips = [luma(f, w, h) for f in clip]
    own, margin = [], []
    for i, d in enumerate(distinct[:len(clips)]):
        own.append(psnr(d, clips[i]))
        margin.append(own[-1] - max(psnr(d, clips[j]) for j in (i - 1, i + 1) if 0 <= j < len(clips)))
    check('played', len(own) == n_images and min(own) > 30.0 and min(margin) > 0.0,
          'luma PSNR of each distinct captured frame against its rendered one: min %.1f dB, '
          'above those against the frames before and after (by %.1f dB or more)' % (min(own), min(margin)))
    diff = [i for i, r in enumerate(runs) for k in r if k >= len(out) or i >= len(hs) or out[k] != hs[i]]
    check('same_bytes', len(hs) == len(runs) and not diff,
          '%d frames of home-stab, %d output frames differ (first: run %s)' % (len(hs), len(diff), diff[:1]))
    j_in = jitter(distinct)
    j_out = jitter([luma(out[r[0]], w, h) for r in runs])
    j_hs = jitter([luma(f, w, h) for f in hs])
    check('jitter', j_out < 0.5 * j_in,
          'input %.3f px, eis-libcamera %.3f px, home-stab %.3f px (RMS, phase correlation)' % (j_in, j_out, j_hs))
    print(json.dumps({'captured': len(raw), 'stabilised': len(out), 'distinct': len(runs),
                      'psnr_min_db': round(min(own), 2), 'jitter_in_px': round(j_in, 3),
                      'jitter_eis_px': round(j_out, 3), 'jitter_home_stab_px': round(j_hs, 3)}))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
