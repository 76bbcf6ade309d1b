"""Photographs for the evaluation, taken from Debian packages only.

Each package is fetched once with `apt-get download` into the cache and only
the files the evaluation uses are unpacked from it (`dpkg-deb --fsys-tarfile`,
the same archive `dpkg -x` unpacks).  Nothing else is read from the network.
Debian's desktop wallpaper and background packages are deliberately not used:
they are kept aside for independent checks.
"""
import gzip
import subprocess
import sys
import tarfile
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

# source name -> (Debian package, directory of its images inside the package)
PACKAGES = {
    "opencv-doc": ("opencv-doc", "usr/share/doc/opencv-doc/examples/data"),
    "skimage": ("python3-skimage", "usr/lib/python3/dist-packages/skimage/data"),
    "visp": ("visp-images-data", "usr/share/visp-images-data/ViSP-images"),
}
LICENCES = {
    "opencv-doc": "OpenCV sample data (Apache-2.0 / BSD-3-Clause, see the package's "
                  "copyright file)",
    "skimage": "scikit-image sample data (BSD-3-Clause per Debian's copyright file; "
               "upstream lists each photograph as public domain or CC0/CC-BY)",
    "visp": "ViSP dataset reference images (GPL-2, Inria)",
}


@dataclass(frozen=True)
class Photo:
    """One photograph: `source` names a PACKAGES entry, `file` is relative to
    its image directory, `crop` = (x, y, w, h) in the file's pixels."""
    source: str
    file: str
    why: str
    crop: tuple = None

    @property
    def name(self):
        stem = Path(self.file).stem
        return stem + ("_crop" if self.crop else "")


class Library:
    """Fetches Debian packages into `cache` and loads photographs from them."""

    def __init__(self, cache):
        self.cache = Path(cache)
        self.versions = {}

    def _deb(self, package):
        debs = sorted(self.cache.glob(f"{package}_*.deb"))
        if not debs:
            self.cache.mkdir(parents=True, exist_ok=True)
            print(f"fetching {package} with apt-get download ...", file=sys.stderr)
            r = subprocess.run(["apt-get", "download", package], cwd=self.cache,
                               capture_output=True, text=True)
            debs = sorted(self.cache.glob(f"{package}_*.deb"))
            if not debs:
                sys.exit(f"cannot fetch {package}: apt-get download said:\n{r.stderr}"
                         f"(run apt-get update, or put {package}_*.deb in {self.cache})")
        self.versions[package] = debs[-1].name.split("_")[1]
        return debs[-1]

    def _unpack(self, source, files):
        """Unpack `files` (relative to the source's image directory; a stored
        .gz is decompressed) into cache/photos/<source>/."""
        package, subdir = PACKAGES[source]
        want = {f"./{subdir}/{f}": f for f in files}
        want.update({k + ".gz": f for k, f in want.items()})
        proc = subprocess.Popen(["dpkg-deb", "--fsys-tarfile", str(self._deb(package))],
                                stdout=subprocess.PIPE)
        with tarfile.open(fileobj=proc.stdout, mode="r|") as tar:
            for member in tar:
                if member.name in want and member.isfile():
                    data = tar.extractfile(member).read()
                    if member.name.endswith(".gz"):
                        data = gzip.decompress(data)
                    out = self.cache / "photos" / source / want[member.name]
                    out.parent.mkdir(parents=True, exist_ok=True)
                    out.write_bytes(data)
        proc.wait()

    def fetch(self, photos):
        """Make sure every photo's file is in the cache."""
        by_source = {}
        for ph in photos:
            by_source.setdefault(ph.source, set()).add(ph.file)
        for source, files in by_source.items():
            missing = [f for f in files if not (self.cache / "photos" / source / f).exists()]
            if missing:
                self._unpack(source, missing)
            else:
                self._deb(PACKAGES[source][0])         # records the version
            still = [f for f in files if not (self.cache / "photos" / source / f).exists()]
            if still:
                sys.exit(f"{PACKAGES[source][0]} has no {', '.join(still)}")

    def grey(self, photo):
        """The photograph as float32 grey, cropped if the photo says so."""
        path = self.cache / "photos" / photo.source / photo.file
        img = cv2.imdecode(np.frombuffer(path.read_bytes(), np.uint8), cv2.IMREAD_GRAYSCALE)
        if img is None:
            raise RuntimeError(f"cannot decode {path}")
        if photo.crop:
            x, y, w, h = photo.crop
            img = img[y:y + h, x:x + w]
        return img.astype(np.float32)
