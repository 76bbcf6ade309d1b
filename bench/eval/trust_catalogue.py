"""The trust evaluation's three sets: what each image is, where it comes from, why.

TUNING: the 40 catalogue photographs of `make eval` (opencv-doc, python3-skimage,
visp-images-data: the photographs the library's thresholds were chosen on) and
scenes from generator variant "A" of scenes.py with tuning seeds.

TEST (sealed: tune nothing on it): photographs from Debian packages the project
never used before, and scenes from generator variant "B" (plus variant A with
other seeds).  Sources of the test photographs:

  palapeli-data        KDE's jigsaw puzzle photographs (usr/share/palapeli/collection)
  python3-sklearn      scikit-learn's sample images (sklearn/datasets/images)
  python3-pywt         PyWavelets' test images (pywt/data/*.npz, 512x512 grey)
  python3-scipy        SciPy's misc.face photograph (scipy/misc/face.dat, bz2 RGB)
  cimg-examples        CImg's example photographs (usr/share/doc/cimg-dev/examples/img)
  libjxl-testdata      JPEG XL conformance photographs (usr/share/libjxl-testdata)
  hugin-data           Hugin's manual: photographs shown in its help pages
  python-matplotlib-data  Matplotlib's sample_data photograph
  gcompris-qt-data     GCompris's activities: monuments (explore_monuments.rcc, 1024 px)
                       and animals in nature (erase.rcc, 1920x1080); "FILE.rcc#K" is the
                       K-th WebP image in the Qt resource file (see trust_data.rcc_webp)

SEALED (static camera only; never look at its numbers while choosing anything):
the test set's static clips were looked at while two thresholds were chosen, so
a third set holds static clips whose backgrounds and mover textures are
photographs no other set uses anywhere (other images of the test set's
packages: GCompris's explore_world_music.rcc, clickgame.rcc (underwater
photographs), erase.rcc, explore_monuments.rcc, explore_world_animals.rcc and
explore_farm_animals.rcc; Hugin's manual), with other seeds (a salt) and a
wider moving share.  `--sets sealed` selects it; it has no still pairs and no
hand-held frames.

Static clips are H.264 round trips (as camera files are), except those whose
Item has condition "raw": a live camera's frames straight from the sensor, with
new noise in every frame (session 13; one in the tuning set, one in the test
set). Condition "gop30" (session 41; one in each of the two sets): an I-frame
every 30 frames, as cameras write, where the encoder's default puts one every
250 (where it refreshes the background, a still fog holds no evidence that it
is still: docs/trust.md, session 41).

The sources the project reserves for independent checks (the developers' guide
lists them) are never used here.  No real static-camera footage with people was
found among the other sources, so the static-camera clips are synthesised only.

Photos were chosen by what they show (looked at as pictures, never by any
method's result on them).

A still-pair group lists Items; an Item is a photograph or a rendered scene,
optionally through a condition (scenes.fog / defocus before the geometry,
low light instead of the protocol's noise on each image).
"""
from dataclasses import dataclass

from data import PACKAGES, LICENCES, Photo
from catalogue import LINEAR, NORMAL

# -- the test set's sources (added to data.PACKAGES for data.Library) --------
TEST_PACKAGES = {
    "palapeli": ("palapeli-data", "usr/share/palapeli/collection"),
    "sklearn": ("python3-sklearn", "usr/lib/python3/dist-packages/sklearn/datasets/images"),
    "pywt": ("python3-pywt", "usr/lib/python3/dist-packages/pywt/data"),
    "scipy": ("python3-scipy", "usr/lib/python3/dist-packages/scipy/misc"),
    "cimg": ("cimg-examples", "usr/share/doc/cimg-dev/examples/img"),
    "libjxl": ("libjxl-testdata", "usr/share/libjxl-testdata"),
    "hugin": ("hugin-data", "usr/share/hugin/xrc/data/help_en_EN"),
    "matplotlib": ("python-matplotlib-data", "usr/share/matplotlib/mpl-data/sample_data"),
    "gcompris": ("gcompris-qt-data", "usr/share/gcompris-qt/rcc"),
}
TEST_LICENCES = {
    "palapeli": "KDE palapeli-data (photographs from Wikimedia Commons; see the package's "
                "copyright file)",
    "sklearn": "scikit-learn sample images (china.jpg, flower.jpg: CC-BY, see "
               "sklearn/datasets/images/README.txt)",
    "pywt": "PyWavelets test data (MIT; aero from the USC-SIPI database, ascent and camera "
            "as in SciPy / scikit-image)",
    "scipy": "SciPy's misc.face (BSD-3-Clause, see the package's copyright file)",
    "cimg": "CImg example images (CeCILL-C / CeCILL, see the package's copyright file)",
    "libjxl": "libjxl conformance test data (BSD-3-Clause / CC, see the package's "
              "copyright file)",
    "hugin": "Hugin manual images (GPL-2+ / CC-BY-SA, see the package's copyright file)",
    "matplotlib": "Matplotlib sample data (grace_hopper.jpg: public domain, US Navy)",
    "gcompris": "GCompris data (photographs under free licences, each listed in the "
                "package's copyright file)",
}
PACKAGES.update(TEST_PACKAGES)
LICENCES.update(TEST_LICENCES)

SETS = ["tuning", "test", "sealed"]
STATIC_ONLY = {"sealed"}            # sets with static clips only


@dataclass(frozen=True)
class Item:
    """One image of a still-pair group: a photograph or a rendered scene
    (kind, variant, seed), optionally through a condition."""
    why: str
    photo: Photo = None
    scene: tuple = None          # (kind, variant "A"/"B", seed name)
    condition: str = None        # None, "fog", "defocus", "lowlight"; static: "raw", "gop30"

    @property
    def name(self):
        base = self.photo.name if self.photo else "_".join(("scene",) + tuple(self.scene))
        return base + (f"_{self.condition}" if self.condition else "")

    @property
    def source(self):
        if self.photo:
            return f"{PACKAGES[self.photo.source][0]}: {self.photo.file}"
        return f"scenes.py {self.scene[0]}, generator {self.scene[1]}, seed {self.scene[2]}"


def _scenes(kind, variant, seeds, why, condition=None):
    return [Item(why, scene=(kind, variant, s), condition=condition) for s in seeds]


# -- tuning photographs (from catalogue.py, same files) ----------------------
def _tp(name):
    for p in LINEAR + NORMAL:
        if p.name == name:
            return p
    raise KeyError(name)


O, S, V = "opencv-doc", "skimage", "visp"
APPLE = Photo(O, "apple.jpg", "apple: smooth shading")
MOON = Photo(S, "moon.png", "lunar surface, few faint craters")

# -- test photographs ------------------------------------------------------
@dataclass(frozen=True)
class NamedPhoto(Photo):
    """A Photo with an explicit short name (file stems collide across packages:
    sklearn's flower.jpg and libjxl's flower.png)."""
    alias: str = None

    @property
    def name(self):
        return self.alias or super().name


def _named(d):
    return {k: NamedPhoto(p.source, p.file, p.why, p.crop, alias=k) for k, p in d.items()}


T = _named({
    "castle": Photo("palapeli", "castle-maintenon.jpg",
                    "château de Maintenon: towers, roofs, window rows, sky"),
    "bridge": Photo("palapeli", "cincinnati-bridge.jpg",
                    "suspension bridge at night: cables, railings, dark sky, reflections"),
    "citrus": Photo("palapeli", "citrus-fruits.jpg",
                    "citrus slices on a light table: repeated round shapes, fine pulp texture"),
    "bee": Photo("palapeli", "european-honey-bee.jpg", "bee on a flower: fine natural texture"),
    "chameleon": Photo("palapeli", "panther-chameleon-female.jpg",
                       "chameleon on leaves: skin texture, foliage"),
    "china": Photo("sklearn", "china.jpg",
                   "Chinese pagoda over a hazy lake: roof lines, trees, a horizon in haze"),
    "dahlia": Photo("sklearn", "flower.jpg", "dahlia on a dark background: petal texture"),
    "aero": Photo("pywt", "aero.npz", "aerial photograph: fields, roads, a river"),
    "ascent": Photo("pywt", "ascent.npz",
                    "stairs and railings from below: strong straight lines, repeated bars"),
    "camera": Photo("pywt", "camera.npz",
                    "cameraman on grass: a tripod's few long edges, flat sky"),
    "face": Photo("scipy", "face.dat", "raccoon in foliage: fur and leaves"),
    "parrot": Photo("cimg", "parrot.ppm", "parrot behind a wire cage: a repeated grid"),
    "milla": Photo("cimg", "milla.bmp", "plush toy on a sofa: soft texture"),
    "flowers": Photo("libjxl", "jxl/flower/flower.png", "flower field: dense natural texture"),
    "room": Photo("libjxl", "jxl/hdr_room.png",
                  "interior: windows, floorboards, ceiling beams, flat white walls"),
    "cliff": Photo("libjxl", "external/wesaturate/500px/cvo9xd_keong_macan_srgb8.png",
                   "rock cliff over the sea, misty mountains on the horizon"),
    "tulips": Photo("libjxl", "external/wesaturate/500px/tmshre_riaphotographs_srgb8.png",
                    "tulips, shallow depth of field: soft texture"),
    "branch": Photo("libjxl", "external/wesaturate/500px/u76c0g_bliznaca_srgb8.png",
                    "blossom branch against a blurred background"),
    "station": Photo("hugin", "800px-C_Marchi-GrandCentral-adj.jpg",
                     "Grand Central hall: windows, arches, long lines, people"),
    "pantheon": Photo("hugin", "360px-Pantheon-150x100-rect-panini.jpg",
                      "Pantheon interior (the lower panel): coffered dome, columns, floor grid",
                      crop=(0, 132, 360, 273)),
    "hopper": Photo("matplotlib", "grace_hopper.jpg",
                    "portrait in uniform: fabric, flags, smooth skin"),
})


def _gm(k, why):
    return Photo("gcompris", f"explore_monuments.rcc#{k}", why)


def _ge(k, why):
    return Photo("gcompris", f"erase.rcc#{k}", why)


T.update(_named({
    # monuments: mostly line-rich, some with few edges on large flat areas or in haze
    "arena": _gm(1, "Roman arena: two storeys of arches, paving, sky"),
    "chambord": _gm(3, "Chambord château over a lawn: roofs, chimneys, clouds"),
    "cathedral": _gm(6, "Gothic cathedral: buttresses, windows, a grass slope"),
    "carcassonne": _gm(7, "walled city: towers and crenellations on a hill"),
    "st_michel": _gm(8, "Mont-Saint-Michel over tidal flats: a horizon, a low island"),
    "aqueduct": _gm(9, "Pont du Gard: three rows of repeated arches over trees"),
    "pyramid_dark": _gm(10, "a pyramid on the desert: few long edges, flat sand and sky"),
    "pyramid_haze": _gm(12, "a pyramid in desert haze: faint edges, smooth gradients"),
    "pyramid_red": _gm(13, "a pyramid on a plain: few long edges, flat ground and sky"),
    "india_gate": _gm(16, "India Gate at night: lit arch, dark sky, palm trees"),
    "mysore": _gm(17, "Mysore palace: arcades, domes, a lawn"),
    "hawa_mahal": _gm(23, "Hawa Mahal: a facade of hundreds of repeated windows"),
    "victoria": _gm(24, "Victoria Memorial: a white marble building, flat sky, a lawn"),
    "columns": _gm(31, "a temple front: a row of repeated columns, steps"),
    "colosseum": _gm(39, "Colosseum: tiers of repeated arches"),
    "berlin": _gm(43, "Berlin cathedral: domes, columns, trees"),
    "brick_church": _gm(44, "brick church with round-arched windows"),
    "brandenburg": _gm(46, "Brandenburg Gate: columns, quadriga, a square"),
    # animals in nature: texture, often on a defocused background
    "rhino": _ge(0, "rhinoceros on a river bank: skin folds, smooth water and sky"),
    "spoonbills": _ge(3, "spoonbills wading: smooth water, reflections"),
    "kingfisher": _ge(8, "kingfisher on a branch: a defocused background"),
    "gorilla": _ge(10, "gorilla in dense foliage"),
    "gibbon": _ge(13, "gibbon in branches and leaves"),
    "chameleon2": _ge(14, "chameleon on a branch among leaves"),
    "crab": _ge(16, "crab on wet sand"),
    "meerkats": _ge(17, "three meerkats: fur, a blurred background"),
    "cheetah": _ge(20, "cheetah in dry grass"),
    "pony": _ge(22, "pony on a hillside: mane, grass, mountains"),
    "penguin": _ge(24, "penguin on gravel"),
    "goat": _ge(29, "long-haired goat on rocks"),
    "giraffe": _ge(31, "giraffe: a patched coat, trees"),
}))

# Pairs per image and setting (5 each: the test set has at least as many
# photographs a group as the tuning set).
PAIRS = {"tuning": 5, "test": 5}
P_CYCLE = [10, 20, 30, 40, 60]      # groups a-d, g: pair i uses p = P_CYCLE[i % 5]
CYCLE_PAIRS = 20                    # pairs per image in groups a-d, g (p cycles 4 times)

GROUPS = [
    # (key, label, kind of settings)
    ("few_edges", "a few long edges, flat areas", "cycle"),
    ("fog_dim", "b fog horizon / dim gradient", "cycle"),
    ("low_light", "c dim and noisy (low light)", "cycle"),
    ("repeated", "d repeated patterns", "cycle"),
    ("line_rich", "e line-rich photographs", "p"),
    ("decay", "f texture decay (p = 20)", "alpha"),
    ("textureless", "g textureless", "cycle"),
]

TUNING_SEEDS = [f"t{i}" for i in range(12)]
TEST_SEEDS = [f"s{i}" for i in range(12)]


def still_groups(which):
    """group key -> [Item] for the tuning or the test set."""
    if which == "tuning":
        sd = TUNING_SEEDS
        return {
            "few_edges": _scenes("few_edges", "A", sd[:10], "3-6 edges crossing flat regions")
            + [Item("white table, a cube and a cylinder: few edges, large flat areas",
                    photo=_tp("image0000")),
               Item("pencil and caps on a plain table", photo=_tp("stuff")),
               Item("dark bars on a white board", photo=_tp("pca_test1"))],
            "fog_dim": _scenes("fog_horizon", "A", sd[:5], "ridge line in fog")
            + _scenes("dim_gradient", "A", sd[:4], "dim smooth gradients")
            + [Item("ornate building against the sky, in fog", photo=_tp("home"),
                    condition="fog"),
               Item("launch towers, in fog", photo=_tp("rocket"), condition="fog"),
               Item("street of houses, in fog", photo=_tp("leuvenA"), condition="fog")],
            "low_light": [Item(f"{p.why}, in low light", photo=p, condition="lowlight")
                          for p in (_tp("building_crop"), _tp("leuvenA"), _tp("blox"),
                                    _tp("basketball1"), _tp("box_in_scene"), _tp("aloeL"),
                                    _tp("motorcycle_left"), _tp("graf1"))]
            + _scenes("few_edges", "A", sd[6:8], "few edges in low light", "lowlight")
            + _scenes("repeated", "A", sd[6:8], "repeated pattern in low light", "lowlight"),
            "repeated": _scenes("repeated", "A", sd[:8], "tiles or a fence")
            + _scenes("lattice", "A", sd[:6], "rectangular tiles or a pegboard")
            + [Item("brick wall", photo=_tp("brick")),
               Item("printed sudoku grid", photo=_tp("sudoku")),
               Item("calibration chessboard", photo=_tp("left01"))],
            "line_rich": [Item(p.why, photo=p) for p in LINEAR],
            "decay": [Item(p.why, photo=p) for p in NORMAL],
            "textureless": _scenes("textureless", "A", sd[:8], "large smooth blobs")
            + [Item("apple: smooth shading", photo=APPLE),
               Item("lunar surface", photo=MOON)],
        }
    if which == "sealed":
        return {}
    sd = TEST_SEEDS
    return {
        "few_edges": _scenes("few_edges", "B", sd[:9], "wall, floor line and a door")
        + _scenes("few_edges", "A", sd[:4], "3-6 edges crossing flat regions (test seeds)")
        + [Item(T[k].why, photo=T[k]) for k in ("pyramid_dark", "pyramid_red", "camera")],
        "fog_dim": _scenes("fog_horizon", "B", sd[:5], "sea horizon in haze")
        + _scenes("dim_gradient", "B", sd[:4], "two dim planes meeting softly")
        + [Item("cliff and misty mountains, in fog", photo=T["cliff"], condition="fog"),
           Item("pagoda over a lake, in fog", photo=T["china"], condition="fog"),
           Item("château, in fog", photo=T["castle"], condition="fog"),
           Item(T["pyramid_haze"].why, photo=T["pyramid_haze"]),
           Item("Mont-Saint-Michel, in fog", photo=T["st_michel"], condition="fog")],
        "low_light": [Item(f"{T[k].why}, in low light", photo=T[k], condition="lowlight")
                      for k in ("room", "station", "bridge", "ascent", "citrus", "flowers",
                                "face", "tulips", "india_gate", "cathedral")]
        + _scenes("few_edges", "B", sd[6:8], "few edges in low light", "lowlight")
        + _scenes("repeated", "B", sd[6:8], "repeated pattern in low light", "lowlight"),
        "repeated": _scenes("repeated", "B", sd[:8], "bricks, windows or a chain-link fence")
        + _scenes("repeated", "B", sd[8:12], "bricks, windows or a chain-link fence")
        + _scenes("lattice", "A", sd[:2], "rectangular tiles or a pegboard (test seeds)")
        + [Item(T[k].why, photo=T[k]) for k in ("parrot", "hawa_mahal", "aqueduct",
                                                 "columns")],
        "line_rich": [Item(T[k].why, photo=T[k]) for k in
                      ("castle", "bridge", "china", "room", "station", "pantheon", "ascent",
                       "camera", "parrot", "cliff", "arena", "chambord", "cathedral",
                       "carcassonne", "mysore", "victoria", "colosseum", "berlin",
                       "brick_church", "brandenburg")],
        "decay": [Item(T[k].why, photo=T[k]) for k in
                  ("citrus", "bee", "chameleon", "dahlia", "flowers", "milla", "tulips",
                   "branch", "aero", "face", "hopper", "rhino", "gorilla", "gibbon",
                   "chameleon2", "crab", "meerkats", "cheetah", "pony", "penguin", "goat",
                   "giraffe")],
        "textureless": _scenes("textureless", "B", sd[:8], "cosine field and a soft shadow")
        + [Item("tulips, defocused to smooth shading", photo=T["tulips"], condition="defocus"),
           Item("cliff and sea, defocused", photo=T["cliff"], condition="defocus"),
           Item("spoonbills on water, defocused", photo=T["spoonbills"], condition="defocus"),
           Item("kingfisher, defocused", photo=T["kingfisher"], condition="defocus")],
    }


# -- consecutive frames: hand-held camera over a scene ----------------------
VIDEO_CONDITIONS = ["day", "low_light", "motion_blur", "shake5", "lens_shading"]
# lens_shading: the day frames through a lens whose illumination falls off towards the corners
# (fixed to the sensor: it does not move with the scene), by this share at the corners, drawn
# per sequence (uncorrected board cameras lose more; an ISP's shading correction leaves less)
LENS_SHADING = (0.1, 0.4)


def video_scenes(which):
    """[Item] the hand-held camera films, per set (each under every condition)."""
    if which == "tuning":
        return [Item("hotel facade and trees", photo=_tp("building_crop")),
                Item("street of brick houses", photo=_tp("leuvenA")),
                Item("gravel", photo=_tp("gravel")),
                Item("painting: ornament texture", photo=_tp("Klimt")),
                Item("notebook and elastic band", photo=_tp("ela_original")),
                Item("apple: smooth shading", photo=APPLE),
                Item("few edges on flat areas", scene=("few_edges", "A", "v0")),
                Item("ridge in fog", scene=("fog_horizon", "A", "v0"))] + _more_scenes("A")
    if which == "sealed":
        return []
    return [Item(T["room"].why, photo=T["room"]),
            Item(T["colosseum"].why, photo=T["colosseum"]),
            Item(T["bee"].why, photo=T["bee"]),
            Item(T["cheetah"].why, photo=T["cheetah"]),
            Item(T["camera"].why, photo=T["camera"]),
            Item(T["cliff"].why, photo=T["cliff"]),
            Item("wall, floor line and a door", scene=("few_edges", "B", "v0")),
            Item("cosine field and a soft shadow", scene=("textureless", "B", "v0"))] + \
        _more_scenes("B")


def _more_scenes(variant):
    """Session 23: one sequence per hard scene let rules fit that sequence; more seeds of the
    scenes that break methods (six of few edges, three each of textureless, fog and dim
    gradients), from the set's own generator."""
    kinds = [("few_edges", 6, "few edges"), ("textureless", 3, "textureless"),
             ("fog_horizon", 3, "horizon in fog"), ("dim_gradient", 3, "dim gradient")]
    return [Item(f"{why}, seed v{i}", scene=(kind, variant, f"v{i}"))
            for kind, n, why in kinds for i in range(1, n + 1)]


# -- static camera, moving objects --------------------------------------------
# The sealed set's photographs: used by no other set, in no suite (checked below).
def _gw(k, why):
    return Photo("gcompris", f"explore_world_music.rcc#{k}", why)


SEALED = _named({
    # backgrounds
    "orchestra": _gw(0, "symphony orchestra on a concert-hall stage: chairs, stands, "
                        "panelled walls (indoor)"),
    "drums": _gw(6, "drum kit and guitar against a plain wall, cables on a carpet "
                    "(indoor, few edges)"),
    "lute": _gw(2, "a long-necked lute on a plain grey studio backdrop (plain, indoor)"),
    "sea_haze": Photo("gcompris", "clickgame.rcc#11",
                      "sea floor in underwater haze: low contrast, smooth gradients (hazy)"),
    "camels": _ge(5, "camels on a flat steppe under a pale sky (plain: large flat areas)"),
    "sun_temple": _gm(19, "carved walls of a sun temple along a passage: dense relief, "
                          "long lines"),
    "office_block": Photo("hugin", "CA_tCA00.jpg",
                          "office block over a lawn: a grid of windows, flat grass"),
    # textures of the moving objects
    "jaguars": Photo("gcompris", "explore_world_animals.rcc#12",
                     "two jaguars on rocks: spotted fur"),
    "hedgehog": Photo("gcompris", "explore_world_animals.rcc#4", "hedgehog in grass: spines"),
    "komodo": Photo("gcompris", "explore_world_animals.rcc#8",
                    "Komodo dragon on rock: scales"),
    "sheep": Photo("gcompris", "explore_farm_animals.rcc#2", "sheep on a pasture: wool, grass"),
})

# Objects of the static clips: their areas add up to a share drawn from this
# range (per set), and the object seeds are salted per set.
STATIC_COVER = {"tuning": (0.15, 0.25), "test": (0.15, 0.25), "sealed": (0.13, 0.26)}
STATIC_SALT = {"tuning": "", "test": "", "sealed": "|sealed-1"}
# ... and a draw is kept only when the share of the frame the objects actually
# change (at most, every 25th frame) lies in this range; else it is redrawn
STATIC_SHARE = (0.10, 0.30)


def static_clips(which):
    """[(background Item, [Photo] textures of the moving objects)]."""
    if which == "tuning":
        tex = [_tp("graf1"), _tp("baboon"), _tp("board"), _tp("chelsea")]
        return [(Item("hotel facade (static), objects moving in front",
                      photo=_tp("building_crop")), tex),
                (Item("office wall and door frame (static), objects moving in front",
                      photo=_tp("basketball1")), tex),
                (Item("aerial view of a town (static, dense texture), objects moving over it",
                      photo=_tp("aero1")), tex),
                (Item("flat wall with few edges (static), objects moving in front",
                      scene=("few_edges", "A", "static0")), tex),
                # added later for more tuning data (after the first four were used)
                (Item("white table, a cube and a cylinder (static, plain, indoor), objects "
                      "moving in front", photo=_tp("image0000")), tex),
                (Item("ornate building in fog (static, hazy), objects moving in front",
                      photo=_tp("home"), condition="fog"), tex),
                # added in session 10 (issue 18: a tripod shot of a horizon in fog)
                (Item("ridge line in fog (static, textureless), objects moving in front",
                      scene=("fog_horizon", "A", "static0")), tex),
                # added in session 13: a live camera's raw frames (no encoder, so every
                # frame's noise is new), another ridge in fog
                (Item("ridge line in fog (static, textureless, raw frames: no encoder), "
                      "objects moving in front", scene=("fog_horizon", "A", "static1"),
                      condition="raw"), tex),
                # added in session 41: a camera's GOP (an I-frame every 30 frames)
                (Item("ridge line in fog (static, textureless, a camera's GOP: an I-frame "
                      "every 30 frames), objects moving in front",
                      scene=("fog_horizon", "A", "static1"), condition="gop30"), tex)]
    if which == "sealed":
        S = SEALED
        tex = [S["jaguars"], S["hedgehog"], S["komodo"], S["sheep"]]
        return [(Item(f"{S[k].why}; static, objects moving in front", photo=S[k]), tex)
                for k in ("orchestra", "sea_haze", "office_block", "drums", "camels",
                          "sun_temple", "lute")]
    tex = [T["citrus"], T["face"], T["bee"], T["aero"]]
    return [(Item("interior (static), objects moving in front", photo=T["room"]), tex),
            (Item("station hall (static), objects moving in front", photo=T["station"]), tex),
            (Item("flower field (static, dense texture), objects moving in front",
                  photo=T["flowers"]), tex),
            (Item("sea horizon in haze (static), objects moving in front",
                   scene=("fog_horizon", "B", "static0")), tex),
            # added in session 13 with the tuning set's raw clip (never looked at before)
            (Item("sea horizon in haze (static, raw frames: no encoder), objects moving in "
                  "front", scene=("fog_horizon", "B", "static1"), condition="raw"), tex),
            # added in session 41 with the tuning set's camera-GOP clip
            (Item("sea horizon in haze (static, a camera's GOP: an I-frame every 30 "
                  "frames), objects moving in front", scene=("fog_horizon", "B", "static1"),
                  condition="gop30"), tex)]


QUICK = {
    "items_per_group": 1, "pairs": 1, "p": [10, 60], "alpha": [0.0, 0.95],
    "video_scenes": 1, "video_frames": 6, "static_frames": 40, "static_clips": 1,
}


def _check_names():
    """Item names are directory names in the cache: unique within a group and
    set, and a photograph name means one file."""
    files = {}
    for which in SETS:
        for g, items in still_groups(which).items():
            names = [it.name for it in items]
            assert len(names) == len(set(names)), (which, g, names)
            for it in items:
                if it.photo:
                    key = it.photo.name + str(it.photo.crop)
                    f = (it.photo.source, it.photo.file)
                    assert files.setdefault(key, f) == f, (key, f, files[key])
    # static clips: names unique over all sets (they are the report's rows)
    clips = [bg.name for s in SETS for bg, _ in static_clips(s)]
    assert len(clips) == len(set(clips)), clips


def _photos(which):
    """Every photograph a set uses, in any suite, as (package source, file)."""
    out = {(it.photo.source, it.photo.file) for its in still_groups(which).values()
           for it in its if it.photo}
    out |= {(it.photo.source, it.photo.file) for it in video_scenes(which) if it.photo}
    for bg, tex in static_clips(which):
        out |= {(p.source, p.file) for p in tex}
        if bg.photo:
            out.add((bg.photo.source, bg.photo.file))
    return out


def _check_sealed():
    """The sealed set shares no photograph with the other sets, and has clips only."""
    others = set().union(*(_photos(s) for s in SETS if s != "sealed"))
    assert not (_photos("sealed") & others), _photos("sealed") & others
    for s in STATIC_ONLY:
        assert not still_groups(s) and not video_scenes(s)


_check_names()
_check_sealed()
