#!/usr/bin/env python3
"""Write the hand-made part of the seed corpus (tests/fuzz/corpus/<target>/seed-*): inputs that
reach each harness's deep paths at once. The rest of the corpus is what `make fuzz` found,
minimised with libFuzzer's -merge=1. Deterministic; run from the repository root."""
import random
import struct
from pathlib import Path

ROOT = Path(__file__).resolve().parent / "corpus"


def u16(v):
    return struct.pack("<H", v & 0xFFFF)


# FLAG_LARGE of both harnesses: all three bits set selects the large size and count ranges (the
# seeds below were written for them); without it sizes and counts are tiny (seed-tiny-*).
LARGE = 0xE000


def api_seed(rng, flags, side=48, theta=40, shapes=10, shift=(3, -2), large=True):
    """fuzz_api.c layout: flags, sizes, theta/keypoints/min-inliers, image recipe, shift."""
    b = u16(flags | (LARGE if large else 0))
    b += u16(side - 32) + u16(side - 32)          # width, height = 32 + v % 25
    b += u16(theta - 16) + u16(120 - 8) + u16(8)  # theta bins, keypoints 120, min inliers 12
    if flags & 0x08:                              # FLAG_STRIDE: padded rows for a and b
        b += u16(5 + 2) + bytes([0]) + u16(3)
    b += bytes([1, rng.randrange(40, 90)]) + u16(3) + u16(3) + u16(shapes)  # shapes on a flat base
    for _ in range(shapes):
        x0, y0 = rng.randrange(side - 8), rng.randrange(side - 8)
        b += u16(x0) + u16(y0) + u16(rng.randrange(4, 20)) + u16(rng.randrange(4, 20))
        b += bytes([rng.randrange(256)])
    b += u16(shift[0] + 6) + u16(shift[1] + 6) + u16(0)
    return b


def main():
    rng = random.Random(7)
    api = ROOT / "api"
    api.mkdir(parents=True, exist_ok=True)
    seeds = {
        "pair": api_seed(rng, 0x000),
        "video": api_seed(rng, 0x100),
        "video-clock": api_seed(rng, 0x300),
        "strides": api_seed(rng, 0x108),
        "render": api_seed(rng, 0x020),
        "corrupt": api_seed(rng, 0x040) + bytes([4]) + bytes(rng.randrange(256) for _ in range(64)),
        "independent": api_seed(rng, 0x010) + bytes([0]) + bytes(rng.randrange(256) for _ in range(200)),
        "large-shift": api_seed(rng, 0x100, side=56, theta=48, shapes=12, shift=(6, 5)),
        "misaligned": u16(0x002) + bytes(12) + u16(7),
        "arena-short": u16(0x004) + bytes(12) + u16(100),
        "raw-size": u16(0x080) + u16(0xFFFF) + u16(31) + bytes(8),
        "config-nan": u16(0x001) + bytes(12) + u16(0) + bytes([0, 0, 0, 0]) + struct.pack("<f", float("nan")) + bytes([6]),
    }
    for name, data in seeds.items():
        (api / f"seed-{name}").write_bytes(data)

    pgm = ROOT / "pgm"
    pgm.mkdir(parents=True, exist_ok=True)
    pix = bytes(rng.randrange(256) for _ in range(64 * 64))
    pgm_seeds = {
        "64x64": b"P5\n64 64\n255\n" + pix,
        "comments": b"P5\n# a comment\n4 2 # another\n255\n" + pix[:8],
        "tabs-crlf": b"P5\t3\r\n3\r\n255\r" + pix[:9],
        "truncated": b"P5\n64 64\n255\n" + pix[:100],
        "maxval-16": b"P5\n2 2\n65535\n" + pix[:8],
        "ascii": b"P2\n2 2\n255\n1 2 3 4\n",
        "huge": b"P5\n4096 4096\n255\n",
    }
    for name, data in pgm_seeds.items():
        (pgm / f"seed-{name}").write_bytes(data)

    y4m = ROOT / "y4m"
    y4m.mkdir(parents=True, exist_ok=True)
    frame = lambda n: b"FRAME\n" + bytes(rng.randrange(256) for _ in range(n))
    y4m_seeds = {
        "420-2frames": b"YUV4MPEG2 W8 H4 F30:1 Ip A1:1 C420jpeg\n" + frame(48) + frame(48),
        "422": b"YUV4MPEG2 W4 H2 C422\n" + frame(16),
        "mono-params": b"YUV4MPEG2 W3 H3 F25:1 XYSCSS=420JPEG Cmono\n" + frame(9),
        "frame-params": b"YUV4MPEG2 W2 H2\nFRAME Ixyz\n" + bytes(6),
        "truncated": b"YUV4MPEG2 W16 H16 C420\n" + frame(100),
        "bad-marker": b"YUV4MPEG2 W2 H2 C420\nFRAMX\n" + bytes(6),
        "444": b"YUV4MPEG2 W2 H2 C444\n" + frame(12),
        "10bit": b"YUV4MPEG2 W2 H2 C420p10\n" + frame(12),
        "huge": b"YUV4MPEG2 W99999 H99999\n",
        "odd-420": b"YUV4MPEG2 W3 H3 C420\n" + frame(14),
        "no-size": b"YUV4MPEG2 F30:1\n",
    }
    for name, data in y4m_seeds.items():
        (y4m / f"seed-{name}").write_bytes(data)

    stab = ROOT / "stab"
    stab.mkdir(parents=True, exist_ok=True)

    def stab_seed(flags, side, lookahead, fmt, shift, frames, extra=b"", large=True, keypoints=120):
        """fuzz_stab.c layout: flags, sizes, keypoints, lookahead, scene, format, pad, shift, frames."""
        b = u16(flags | (LARGE if large else 0)) + u16(side // 2 - 16) + u16(side // 2 - 16) + extra
        b += u16(keypoints - 8) + u16(lookahead) + bytes([90]) + u16(8)
        for _ in range(8):
            x0, y0 = rng.randrange(50), rng.randrange(50)
            b += u16(x0) + u16(y0) + u16(x0 + rng.randrange(4, 14)) + u16(y0 + rng.randrange(4, 14))
            b += bytes([rng.randrange(256)])
        b += u16(fmt) + u16(2) + u16(shift[0] + 3) + u16(shift[1] + 3) + u16(frames - 1)
        return b + bytes(16)

    stab_seeds = {
        "grey-causal": stab_seed(0, 48, 0, 5, (1, 2), 4),
        "i420-lookahead": stab_seed(0, 64, 2, 1, (2, -1), 5),
        "nv12": stab_seed(0, 48, 1, 2, (-1, 1), 3),
        "yuyv": stab_seed(0, 40, 0, 3, (1, 0), 3),
        "i422": stab_seed(0, 48, 0, 4, (0, 1), 3),
        "bad-format": stab_seed(0, 48, 0, 7, (0, 0), 2),
        "arena-short": stab_seed(4, 48, 0, 5, (0, 0), 1),
        "config-nan": stab_seed(2, 48, 0, 5, (1, 1), 2, extra=struct.pack("<f", float("nan")) + bytes(4) + bytes([0])),
    }
    for name, data in stab_seeds.items():
        (stab / f"seed-{name}").write_bytes(data)

    # tiny configs (the fast executions most of a campaign runs), from their own generator so the
    # seeds above stay as they were
    rng = random.Random(8)
    tiny_api = {
        "pair": api_seed(rng, 0x000, side=34, theta=20, shapes=8, shift=(2, -1), large=False),
        "video-render": api_seed(rng, 0x120, side=32, theta=16, shapes=6, large=False),
        "refine-corrupt": api_seed(rng, 0x440, side=36, theta=24, shapes=8, large=False)
        + bytes([4]) + bytes(rng.randrange(256) for _ in range(64)),
        "exact": api_seed(rng, 0x800, side=33, theta=18, shapes=8, large=False),
    }
    for name, data in tiny_api.items():
        (api / f"seed-tiny-{name}").write_bytes(data)
    tiny_stab = {
        "grey": stab_seed(0, 32, 0, 5, (1, 1), 3, large=False, keypoints=24),
        "i420-lookahead": stab_seed(0, 34, 1, 1, (1, -1), 3, large=False, keypoints=16),
        "no-push": stab_seed(0, 32, 0, 5, (0, 0), 1, large=False, keypoints=8),
    }
    for name, data in tiny_stab.items():
        (stab / f"seed-tiny-{name}").write_bytes(data)


if __name__ == "__main__":
    main()
