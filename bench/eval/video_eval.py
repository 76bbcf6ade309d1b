"""Synthetic video: a virtual hand-held camera over a large real photograph.

The photograph (the "world", scaled to cover WORLD_SCALE x the frame) is
viewed through a homography M_t that maps frame pixels to world pixels:

    M_t = T(centre_t) R(roll_t) S(zoom_t) P(tilt_t) T(-frame centre)

centre_t follows a smooth Lissajous path plus hand-shake jitter (an AR(1)
process, correlated from frame to frame), roll a slow swing plus jitter, zoom
a slow breathing and P a small perspective (keystone) that drifts.  Frames are
640x360, grey, with Gaussian noise; with motion blur a frame is the mean of
BLUR_SAMPLES renders over half a frame interval around its time.  The ground
truth from frame t-1 to frame t is M_t^-1 M_(t-1).

Categories follow the paper's TUM table (structure x texture).  Scenes whose
photographs have texture are used as they are; the no-texture categories use
photographs that lack texture, or photographs whose texture was removed:
  flatten  3 passes of a 9x9 median (keeps straight edges, removes fine
           texture), then a 2 px Gaussian;
  defocus  a Gaussian blur of the world (sigma in world pixels): no edges left;
  decay    I + alpha (128 - I), the paper's texture decay.
"""
from dataclasses import dataclass

import cv2
import numpy as np

from common import CROP_H, CROP_W, NOISE_SIGMA, corner_error, rng_for, to_u8, write_pgm

WORLD_SCALE = 1.5        # world is 1.5x the frame (960x540) before zoom
BLUR_SAMPLES = 7
PATH_FRAMES = 60         # the camera path's time scale: shorter runs show its start


@dataclass(frozen=True)
class Scene:
    category: str
    photo: object             # data.Photo
    flatten: bool = False
    defocus: float = 0.0
    decay: float = 0.0
    blur: bool = False        # motion blur

    @property
    def name(self):
        ops = [("flat", self.flatten), (f"defocus{self.defocus:g}", self.defocus),
               (f"decay{self.decay:g}", self.decay), ("blur", self.blur)]
        return "_".join([self.photo.name] + [n for n, on in ops if on])


def world_image(lib, scene):
    img = lib.grey(scene.photo)
    if scene.flatten:
        u8 = to_u8(img)
        for _ in range(3):
            u8 = cv2.medianBlur(u8, 9)
        img = cv2.GaussianBlur(u8.astype(np.float32), (0, 0), 2.0)
    w, h = round(CROP_W * WORLD_SCALE), round(CROP_H * WORLD_SCALE)
    ih, iw = img.shape
    s = max(w / iw, h / ih)
    img = cv2.resize(img, (round(iw * s), round(ih * s)),
                     interpolation=cv2.INTER_AREA if s < 1 else cv2.INTER_CUBIC)
    y0, x0 = (img.shape[0] - h) // 2, (img.shape[1] - w) // 2
    img = img[y0:y0 + h, x0:x0 + w]
    if scene.defocus:
        img = cv2.GaussianBlur(img, (0, 0), scene.defocus)
    return img + scene.decay * (128.0 - img)


class Camera:
    """The pose at (fractional) frame time t, as the 3x3 M_t."""

    path_frames = PATH_FRAMES   # the path's time scale (a subclass may slow it)

    def __init__(self, key, n_frames, world_shape):
        rng = rng_for(key)
        wh, ww = world_shape
        self.centre = np.array([(ww - 1) / 2, (wh - 1) / 2])
        # room to move: half the slack between world and the zoomed frame
        zmax = 1.05
        self.amp = np.array([(ww - CROP_W * zmax) / 2 - 25, (wh - CROP_H * zmax) / 2 - 25])
        self.freq = rng.uniform(0.6, 1.2, 2)            # periods per sequence
        self.phase = rng.uniform(0, 2 * np.pi, 6)
        # hand-shake: AR(1) jitter of x, y (px), roll (rad); one sample a frame
        jitter = np.zeros((n_frames + 2, 3))
        sd = np.array([1.5, 1.5, np.radians(0.15)])
        for t in range(1, n_frames + 2):
            jitter[t] = 0.7 * jitter[t - 1] + rng.normal(0, sd)
        self.jitter = jitter

    def M(self, t):
        u = t / self.path_frames
        ph = self.phase
        jitter = np.array([np.interp(t + 1, np.arange(len(self.jitter)), self.jitter[:, k])
                           for k in range(3)])
        pos = self.centre + self.amp * np.sin(2 * np.pi * self.freq * u + ph[:2]) + jitter[:2]
        roll = np.radians(2.0) * np.sin(2 * np.pi * 0.7 * u + ph[2]) + jitter[2]
        zoom = 1.0 + 0.04 * np.sin(2 * np.pi * 0.5 * u + ph[3])
        gx = 4e-5 * np.sin(2 * np.pi * 0.4 * u + ph[4])   # ~ +-1.3 % keystone at the edges
        gy = 4e-5 * np.sin(2 * np.pi * 0.3 * u + ph[5])
        c, s = np.cos(roll), np.sin(roll)
        T = np.array([[1, 0, pos[0]], [0, 1, pos[1]], [0, 0, 1]])
        R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
        S = np.diag([zoom, zoom, 1.0])
        P = np.array([[1, 0, 0], [0, 1, 0], [gx, gy, 1]])
        C = np.array([[1, 0, -(CROP_W - 1) / 2], [0, 1, -(CROP_H - 1) / 2], [0, 0, 1]])
        return T @ R @ S @ P @ C


def render(world, M):
    return cv2.warpPerspective(world, M, (CROP_W, CROP_H),
                               flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                               borderMode=cv2.BORDER_REFLECT)


def build(lib, scenes, n_frames, workdir):
    """Render each scene's sequence and return frame-pair records."""
    records = []
    for seq, scene in enumerate(scenes):
        world = world_image(lib, scene)
        cam = Camera(scene.name, n_frames, world.shape)
        noise = rng_for(scene.name + "|noise")
        d = workdir / scene.category / scene.name
        d.mkdir(parents=True, exist_ok=True)
        frames, Ms = [], []
        for t in range(n_frames):
            if scene.blur:
                ts = t + np.linspace(-0.25, 0.25, BLUR_SAMPLES)
                img = np.mean([render(world, cam.M(u)) for u in ts], axis=0)
            else:
                img = render(world, cam.M(t))
            frames.append(to_u8(img + noise.normal(0, NOISE_SIGMA, img.shape)))
            Ms.append(cam.M(t))
            write_pgm(d / f"{t:03d}.pgm", frames[-1])
        for t in range(1, n_frames):
            Ht = np.linalg.inv(Ms[t]) @ Ms[t - 1]
            Ht /= Ht[2, 2]
            records.append({
                "suite": "video", "group": scene.category, "image": scene.name,
                "idx": t, "A": str(d / f"{t - 1:03d}.pgm"), "B": str(d / f"{t:03d}.pgm"),
                "imgA": frames[t - 1], "imgB": frames[t], "H_true": Ht,
                "err_identity": corner_error(np.eye(3), Ht)})
    return records
