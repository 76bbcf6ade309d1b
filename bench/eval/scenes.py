"""Procedurally rendered hard scenes, and the photometric conditions that break
registration, for the trust evaluation (trust.py).

Every scene is a float32 grey image (0..255) rendered from a name: the same
(kind, variant, seed) always gives the same picture, whatever else is rendered.
Two generator variants exist for every kind, so the sealed test set can use
scenes the tuning set never showed in form, not only in seed:

  kind          variant "A" (tuning)                     variant "B" (test)
  few_edges     3-6 straight edges crossing the frame    a wall, a floor line and a door
                between flat regions (half-planes)       (4-5 edges), in perspective
  fog_horizon   sky gradient over a ridge line (random   a sea horizon with faint swell
                walk), in fog                            bands and low hills, in haze
  dim_gradient  dim linear + radial gradients, one       two dim planes meeting in a soft
                soft blob                                corner, vignetted
  repeated      floor tiles / picket fence               brick bond / window grid /
                                                         chain-link lattice
  lattice       rectangular tiles / pegboard (two        (none: tuning only)
                unequal periods)
  textureless   a few large Gaussian blobs               a low-frequency cosine field and
                                                         one soft shadow

Photometric conditions, applied to photographs or scenes:
  fog(img)       contrast down to 12-25 % towards a bright fog level, 1.5 px blur
  defocus(img)   heavy Gaussian blur (sigma 8) and texture decay 0.4: no edges left
  low_light()    one capture: brightness scaled to 10-25 %, photon shot noise
                 (1020 e- at full scale) and read noise (1.5 DN), quantised to 8 bit
"""
import cv2
import numpy as np

from common import rng_for

KINDS = ["few_edges", "fog_horizon", "dim_gradient", "repeated", "lattice", "textureless"]
VARIANTS = {"A": "tuning generator", "B": "test generator"}


def render(kind, variant, seed, w, h):
    """Scene `kind` from generator `variant` ("A" or "B") for `seed` (a name),
    w x h px, float32 in 0..255."""
    rng = rng_for(f"scene|{kind}|{variant}|{seed}")
    fn = _RENDERERS[(kind, variant)]
    img = fn(rng, w, h)
    return np.clip(img, 0, 255).astype(np.float32)


def _grid(w, h):
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    return x, y


def _edge(d, width=0.7):
    """Anti-aliased step across a signed distance d (px)."""
    return 0.5 * (1.0 + np.tanh(d / width))


def _illumination(rng, w, h, amp):
    """A gentle illumination gradient, +-amp over the frame."""
    x, y = _grid(w, h)
    gx, gy = rng.uniform(-1, 1, 2)
    return amp * (gx * (x / w - 0.5) + gy * (y / h - 0.5))


def _perspective(img, rng, strength):
    """Warp by a random mild homography (corners moved by up to strength x size)."""
    h, w = img.shape
    src = np.float32([[0, 0], [w - 1, 0], [0, h - 1], [w - 1, h - 1]])
    dst = (src + rng.uniform(-strength, strength, (4, 2)) * [w, h]).astype(np.float32)
    Hm = cv2.getPerspectiveTransform(src, dst)
    return cv2.warpPerspective(img, Hm, (w, h), flags=cv2.INTER_LINEAR,
                               borderMode=cv2.BORDER_REFLECT)


# -- few long edges on large flat areas ------------------------------------
def _few_edges_a(rng, w, h):
    x, y = _grid(w, h)
    img = np.full((h, w), rng.uniform(90, 170), np.float32)
    n = int(rng.integers(3, 7))
    for _ in range(n):
        px, py = rng.uniform(0.2, 0.8) * w, rng.uniform(0.2, 0.8) * h
        th = rng.uniform(0, np.pi)
        d = (x - px) * np.cos(th) + (y - py) * np.sin(th)
        img += rng.choice([-1, 1]) * rng.uniform(15, 45) * _edge(d)
    return img + _illumination(rng, w, h, 12)


def _few_edges_b(rng, w, h):
    # a wall over a floor, a door in the wall (and maybe a ceiling line), then a
    # mild perspective: 4-5 edges, everything else flat
    x, y = _grid(w, h)
    wall, floor = rng.uniform(110, 200), rng.uniform(50, 120)
    fy = rng.uniform(0.62, 0.8) * h
    img = wall + (floor - wall) * _edge(y - fy)
    dw, dh = rng.uniform(0.12, 0.2) * w, rng.uniform(0.45, 0.55) * h
    dx = rng.uniform(0.15, 0.85 - dw / w) * w
    door = _edge(x - dx) * _edge(dx + dw - x) * _edge(y - (fy - dh)) * _edge(fy - y)
    img += (rng.uniform(40, 90) - wall) * door
    if rng.uniform() < 0.5:
        img += rng.uniform(-25, -10) * _edge(rng.uniform(0.08, 0.18) * h - y)
    img = img + _illumination(rng, w, h, 10)
    return _perspective(img.astype(np.float32), rng, 0.05)


# -- horizons in fog, dim gradients -----------------------------------------
def _ridge(rng, w, amp, smooth):
    walk = np.cumsum(rng.normal(0, 1, w + 4 * smooth))
    walk = cv2.GaussianBlur(walk.reshape(1, -1), (0, 0), smooth).ravel()[2 * smooth:2 * smooth + w]
    walk -= walk.mean()
    return amp * walk / (np.abs(walk).max() + 1e-6)


def _fog_horizon_a(rng, w, h):
    x, y = _grid(w, h)
    fogv = rng.uniform(150, 200)
    hy = rng.uniform(0.4, 0.65) * h + rng.uniform(-0.05, 0.05) * (x - w / 2)
    ridge = hy - 20 - _ridge(rng, w, rng.uniform(10, 40), 25)[None, :]
    sky = fogv + rng.uniform(15, 40) * (1 - y / hy) * (y < hy)
    land = fogv - rng.uniform(20, 45) - 0.04 * (y - hy).clip(0)
    img = sky + (land - sky) * _edge(y - ridge, 1.5)
    c = rng.uniform(0.15, 0.3)                 # fog: contrast left
    img = fogv + c * (img - fogv)
    return cv2.GaussianBlur(img.astype(np.float32), (0, 0), rng.uniform(1.5, 3.0))


def _fog_horizon_b(rng, w, h):
    x, y = _grid(w, h)
    haze = rng.uniform(140, 190)
    hy = rng.uniform(0.45, 0.6) * h
    tilt = rng.uniform(-0.03, 0.03)
    yh = y - hy - tilt * (x - w / 2)
    sky = haze + rng.uniform(10, 30) * (-yh / h).clip(0, 1)
    sea = haze - rng.uniform(8, 20) - 0.05 * yh.clip(0) \
        + rng.uniform(0.8, 2.0) * np.sin(2 * np.pi * yh.clip(0) ** 1.3 / rng.uniform(25, 45))
    img = sky + (sea - sky) * _edge(yh, 1.0)
    hills = _ridge(rng, w, rng.uniform(8, 25), 40)[None, :] + 15
    hill = _edge(yh + hills, 2.0) * _edge(-yh, 1.0)
    img += -rng.uniform(5, 12) * hill
    # a soft sun glow
    sx, sy = rng.uniform(0.2, 0.8) * w, hy - rng.uniform(0.1, 0.3) * h
    img += rng.uniform(10, 25) * np.exp(-((x - sx) ** 2 + (y - sy) ** 2) / (2 * (0.15 * w) ** 2))
    return cv2.GaussianBlur(img.astype(np.float32), (0, 0), 1.2)


def _dim_gradient_a(rng, w, h):
    x, y = _grid(w, h)
    base = rng.uniform(20, 50)
    g = rng.uniform(-1, 1, 2)
    img = base + rng.uniform(10, 25) * (g[0] * x / w + g[1] * y / h)
    cx, cy = rng.uniform(0.2, 0.8) * w, rng.uniform(0.2, 0.8) * h
    img += rng.uniform(10, 30) * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * (0.3 * w) ** 2))
    bx, by, bs = rng.uniform(0.2, 0.8) * w, rng.uniform(0.2, 0.8) * h, rng.uniform(30, 80)
    img += rng.choice([-1, 1]) * rng.uniform(5, 12) * \
        np.exp(-((x - bx) ** 2 + (y - by) ** 2) / (2 * bs ** 2))
    return img


def _dim_gradient_b(rng, w, h):
    x, y = _grid(w, h)
    cx = rng.uniform(0.3, 0.7) * w
    d = (x - cx) - rng.uniform(-0.15, 0.15) * (y - h / 2)
    left, right = rng.uniform(25, 45), rng.uniform(35, 60)
    img = left + (right - left) * _edge(d, rng.uniform(6, 14))
    img += 0.02 * rng.uniform(-1, 1) * (y - h / 2)
    r2 = ((x - w / 2) / w) ** 2 + ((y - h / 2) / h) ** 2
    return img * (1 - rng.uniform(0.3, 0.6) * r2)


# -- repeated patterns -----------------------------------------------------
def _supersampled(fn, w, h, ss=2):
    x, y = _grid(w * ss, h * ss)
    img = fn(x / ss, y / ss)
    return cv2.resize(img.astype(np.float32), (w, h), interpolation=cv2.INTER_AREA)


def _repeated_a(rng, w, h):
    kind = int(rng.integers(2))
    if kind == 0:                              # square floor tiles, thin grout
        period = rng.uniform(40, 80)
        grout = rng.uniform(2, 5)
        tile, gv = rng.uniform(130, 200), rng.uniform(50, 100)
        shade = rng.normal(0, 6, (64, 64))

        def f(x, y):
            u, v = x / period, y / period
            on = ((u % 1) * period > grout) & ((v % 1) * period > grout)
            s = shade[np.floor(v).astype(int) % 64, np.floor(u).astype(int) % 64]
            return np.where(on, tile + s, gv)
    else:                                      # picket fence against a flat wall
        period = rng.uniform(30, 60)
        width = rng.uniform(0.4, 0.7) * period
        wallv, wood = rng.uniform(60, 110), rng.uniform(160, 220)
        rails = sorted(rng.uniform(0.2, 0.8, 2) * h)

        def f(x, y):
            picket = (x % period) < width
            rail = (np.abs(y - rails[0]) < 8) | (np.abs(y - rails[1]) < 8)
            return np.where(picket | rail, wood, wallv) + 0.0 * y
    img = _supersampled(f, w, h) + _illumination(rng, w, h, 20)
    return _perspective(img, rng, 0.04)


def _repeated_b(rng, w, h):
    kind = int(rng.integers(3))
    if kind == 0:                              # running-bond brick wall
        bw, bh = rng.uniform(50, 90), rng.uniform(20, 32)
        mortar = rng.uniform(2, 4)
        brick, mv = rng.uniform(100, 160), rng.uniform(170, 210)
        shade = rng.normal(0, 8, (64, 64))

        def f(x, y):
            row = np.floor(y / bh)
            xs = x + (row % 2) * bw / 2
            on = ((xs % bw) > mortar) & ((y % bh) > mortar)
            s = shade[row.astype(int) % 64, np.floor(xs / bw).astype(int) % 64]
            return np.where(on, brick + s, mv)
    elif kind == 1:                            # facade: a grid of windows
        px, py = rng.uniform(60, 110), rng.uniform(70, 120)
        fw, fh = rng.uniform(0.45, 0.7), rng.uniform(0.45, 0.7)
        wallv, glass = rng.uniform(140, 200), rng.uniform(30, 80)

        def f(x, y):
            on = ((x % px) < fw * px) & ((y % py) < fh * py)
            return np.where(on, glass, wallv)
    else:                                      # chain-link fence: a diagonal lattice
        period = rng.uniform(25, 45)
        wire = rng.uniform(1.5, 3)
        bg, metal = rng.uniform(70, 130), rng.uniform(170, 230)

        def f(x, y):
            a = np.abs(((x + y) / np.sqrt(2)) % (period / np.sqrt(2)))
            b = np.abs(((x - y) / np.sqrt(2)) % (period / np.sqrt(2)))
            return np.where((a < wire) | (b < wire), metal, bg)
    img = _supersampled(f, w, h) + _illumination(rng, w, h, 20)
    return _perspective(img, rng, 0.04)


def _lattice_a(rng, w, h):
    """Tuning only (added when the test set's brick walls and window grids showed that a
    pattern repeating along two directions with two periods defeats a one-direction alias
    test): rectangular tiles or a pegboard, periods unequal in x and y."""
    kind = int(rng.integers(2))
    px, py = rng.uniform(35, 90), rng.uniform(22, 60)
    if kind == 0:                              # rectangular wall tiles, thin grout
        grout = rng.uniform(2, 4)
        tile, gv = rng.uniform(140, 210), rng.uniform(60, 110)
        shade = rng.normal(0, 6, (64, 64))

        def f(x, y):
            on = ((x % px) > grout) & ((y % py) > grout)
            s = shade[np.floor(y / py).astype(int) % 64, np.floor(x / px).astype(int) % 64]
            return np.where(on, tile + s, gv)
    else:                                      # pegboard: dark holes in a light board
        r = rng.uniform(0.12, 0.22) * min(px, py)
        board, hole = rng.uniform(150, 210), rng.uniform(20, 60)

        def f(x, y):
            dx, dy = (x % px) - px / 2, (y % py) - py / 2
            return np.where(dx * dx + dy * dy < r * r, hole, board)
    img = _supersampled(f, w, h) + _illumination(rng, w, h, 20)
    return _perspective(img, rng, 0.04)


# -- textureless -----------------------------------------------------------
def _textureless_a(rng, w, h):
    x, y = _grid(w, h)
    img = np.full((h, w), rng.uniform(90, 160), np.float32)
    for _ in range(int(rng.integers(3, 7))):
        cx, cy = rng.uniform(0, w), rng.uniform(0, h)
        s = rng.uniform(80, 250)
        img += rng.uniform(-50, 50) * np.exp(-((x - cx) ** 2 + (y - cy) ** 2) / (2 * s * s))
    return img


def _textureless_b(rng, w, h):
    x, y = _grid(w, h)
    img = np.full((h, w), rng.uniform(90, 160), np.float32)
    for _ in range(4):
        lam = rng.uniform(300, 900)
        th = rng.uniform(0, np.pi)
        img += rng.uniform(8, 25) * np.cos(2 * np.pi * (x * np.cos(th) + y * np.sin(th)) / lam
                                           + rng.uniform(0, 2 * np.pi))
    # one soft shadow: a blurred ellipse
    mask = np.zeros((h, w), np.float32)
    cv2.ellipse(mask, (int(rng.uniform(0.2, 0.8) * w), int(rng.uniform(0.2, 0.8) * h)),
                (int(rng.uniform(60, 160)), int(rng.uniform(40, 120))),
                float(rng.uniform(0, 180)), 0, 360, 1.0, -1)
    return img - rng.uniform(10, 25) * cv2.GaussianBlur(mask, (0, 0), 30)


_RENDERERS = {
    ("few_edges", "A"): _few_edges_a, ("few_edges", "B"): _few_edges_b,
    ("fog_horizon", "A"): _fog_horizon_a, ("fog_horizon", "B"): _fog_horizon_b,
    ("dim_gradient", "A"): _dim_gradient_a, ("dim_gradient", "B"): _dim_gradient_b,
    ("repeated", "A"): _repeated_a, ("repeated", "B"): _repeated_b,
    ("lattice", "A"): _lattice_a,
    ("textureless", "A"): _textureless_a, ("textureless", "B"): _textureless_b,
}


# -- photometric conditions ------------------------------------------------
def fog(img, rng):
    """A photograph seen through fog: contrast to 12-25 % towards a bright fog
    level, then a 1.5 px blur (scattering)."""
    fogv = rng.uniform(160, 200)
    out = fogv + rng.uniform(0.12, 0.25) * (img - fogv)
    return cv2.GaussianBlur(out.astype(np.float32), (0, 0), 1.5)


def defocus(img, sigma=8.0, decay=0.4):
    """Strong defocus and texture decay: smooth shading only."""
    out = cv2.GaussianBlur(img.astype(np.float32), (0, 0), sigma)
    return out + decay * (128.0 - out)


FULL_WELL_E = 1020.0          # electrons at 255 DN (0.25 DN per electron)
READ_NOISE_DN = 1.5


def low_light_params(rng):
    return {"gain": float(rng.uniform(0.10, 0.25))}


def low_light(img, gain, rng):
    """One low-light capture of `img` (float, 0..255 as in daylight): brightness
    scaled by `gain`, Poisson shot noise, Gaussian read noise, 8-bit."""
    e = np.clip(img, 0, 255) * gain * (FULL_WELL_E / 255.0)
    e = rng.poisson(e).astype(np.float32)
    dn = e * (255.0 / FULL_WELL_E) + rng.normal(0, READ_NOISE_DN, img.shape)
    return np.clip(np.rint(dn), 0, 255).astype(np.uint8)
