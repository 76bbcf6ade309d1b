"""Shared pieces of the evaluation: the protocol's constants, scoring, image I/O
and a small parallel map.

Conventions: H maps image A's pixel coordinates to image B's (x right, y down,
top-left pixel centre at (0, 0)), which is both home-register's and OpenCV's.
"""
import concurrent.futures
import subprocess
import zlib

import cv2
import numpy as np

# The paper's synthetic-pair protocol.
FULL_W, FULL_H = 854, 480          # frame the perturbation is applied to
CROP_W, CROP_H = 640, 360          # evaluated images (and video frames)
NOISE_SIGMA = 2.5
MIN_INLIERS = 20                   # the paper's failure rule, with det(H/h22) > 0
CORNERS = np.array([[0, 0], [CROP_W - 1, 0], [0, CROP_H - 1],
                    [CROP_W - 1, CROP_H - 1]], float)


def rng_for(key):
    """A generator seeded by a name, not by run order, so any subset of the
    evaluation (--quick, one set, one method) reproduces the same data."""
    return np.random.default_rng(zlib.crc32(key.encode()))


# --------------------------------------------------------------------------
# Geometry and scoring
# --------------------------------------------------------------------------
def project(H, pts):
    q = np.c_[pts, np.ones(len(pts))] @ np.asarray(H, float).T
    return q[:, :2] / q[:, 2:3]


def corner_error(H_est, H_true):
    """Mean distance of the four image corners mapped by H_est and H_true."""
    with np.errstate(all="ignore"):
        d = np.linalg.norm(project(H_est, CORNERS) - project(H_true, CORNERS),
                           axis=1).mean()
    return float(d) if np.isfinite(d) else float("inf")


def usable(H):
    return H is not None and np.all(np.isfinite(H)) and abs(H[2, 2]) > 1e-12


def passes_paper_rule(H, inliers):
    """The paper's failure rule: at least 20 inliers and det(H / H22) > 0."""
    return usable(H) and (inliers or 0) >= MIN_INLIERS \
        and np.linalg.det(H / H[2, 2]) > 0


def photometric_rmse(A, B, H):
    """RMSE between A warped by H into B's frame and B, over the overlap
    (pixels of B whose preimage lies inside A).  None if there is no overlap."""
    h, w = B.shape
    warped = cv2.warpPerspective(A.astype(np.float32), H, (w, h),
                                 flags=cv2.INTER_LINEAR,
                                 borderMode=cv2.BORDER_CONSTANT, borderValue=-1)
    valid = cv2.warpPerspective(np.ones_like(A, np.uint8), H, (w, h),
                                flags=cv2.INTER_NEAREST) > 0
    valid &= warped >= 0
    if valid.sum() < 0.05 * w * h:
        return None
    d = warped[valid] - B[valid].astype(np.float32)
    return float(np.sqrt(np.mean(d * d)))


# --------------------------------------------------------------------------
# Images
# --------------------------------------------------------------------------
def cover_resize(img, w, h):
    """Scale so the image covers w x h, then centre-crop; float32."""
    ih, iw = img.shape
    s = max(w / iw, h / ih)
    nw, nh = max(w, round(iw * s)), max(h, round(ih * s))
    interp = cv2.INTER_AREA if s < 1 else cv2.INTER_CUBIC
    img = cv2.resize(img, (nw, nh), interpolation=interp).astype(np.float32)
    x0, y0 = (nw - w) // 2, (nh - h) // 2
    return np.clip(img[y0:y0 + h, x0:x0 + w], 0, 255)


def to_u8(img):
    return np.clip(np.rint(img), 0, 255).astype(np.uint8)


def write_pgm(path, img):
    h, w = img.shape
    path.write_bytes(b"P5\n%d %d\n255\n" % (w, h) + img.tobytes())


# --------------------------------------------------------------------------
# Running methods over many inputs
# --------------------------------------------------------------------------
def parallel_map(fn, items, jobs):
    """fn over items in `jobs` threads.  OpenCV and the HOME subprocess both
    release the GIL, so threads give real parallelism here."""
    if jobs <= 1:
        return [fn(x) for x in items]
    with concurrent.futures.ThreadPoolExecutor(jobs) as ex:
        return list(ex.map(fn, items))


def git_describe(where):
    """The commit of the work tree `where` lies in (the HOME binary's build)."""
    try:
        return subprocess.run(["git", "-C", str(where), "describe", "--always", "--dirty"],
                              capture_output=True, text=True).stdout.strip() or "?"
    except OSError:
        return "?"
