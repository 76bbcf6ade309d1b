"""Which photographs the evaluation uses, and why.

Chosen by what they show (the baselines' keypoint counts on a few trial pairs
were looked at while choosing, never HOME's results): real photographs only
(generated patterns such as opencv-doc's chessboard.png and cards.png are left
out), from Debian's opencv-doc, python3-skimage and visp-images-data.
The first entries of each list (QUICK_*) form the CI subset; they span all
three packages so CI exercises every fetch path.
"""
from data import Photo
from video_eval import Scene

O, S, V = "opencv-doc", "skimage", "visp"

LINEAR = [  # straight structures dominate; many have large flat regions
    Photo(O, "building.jpg", "hotel facade: window grid, flat wall panels (crop without trees)",
          crop=(150, 0, 712, 400)),
    Photo(O, "ela_original.jpg",
          "notebook and elastic band: long straight edges, almost no texture"),
    Photo(S, "brick.png", "brick wall: mortar lines, repetitive"),
    Photo(V, "mbt/cube/image0000.pgm", "white table, cylinder, cube: few edges on flat surfaces"),
    Photo(O, "sudoku.png", "printed sudoku grid photographed at an angle"),
    Photo(O, "left01.jpg", "calibration chessboard held in an office"),
    Photo(O, "right05.jpg", "calibration chessboard, another pose and camera"),
    Photo(O, "stuff.jpg", "pencil, lighter and caps on a plain table: few straight edges"),
    Photo(O, "licenseplate_motion.jpg",
          "car rear with motion blur: horizontal structures, texture smeared"),
    Photo(O, "blox.jpg", "wooden blocks: straight edges, flat faces"),
    Photo(O, "pca_test1.jpg", "dark bars on a white board: straight edges only"),
    Photo(O, "basketball1.png", "office wall and door frame, two people: large flat areas"),
    Photo(O, "text_defocus.jpg", "defocused printed page: rows of text blurred into bands"),
    Photo(O, "leuvenA.jpg", "street of brick houses: roof and window lines, cobblestones"),
    Photo(O, "home.jpg", "ornate building against the sky"),
    Photo(S, "rocket.jpg", "launch towers at night: lattice lines on a dark sky"),
    Photo(S, "page.png", "photographed printed page: parallel text lines"),
    Photo(V, "AprilTag/AprilTag.pgm", "square tags on a desk: square edges, flat desk"),
    Photo(V, "mbt/cube/image0150.pgm", "the cube/cylinder table seen from another pose"),
    Photo(V, "mbt-depth/castel/castel/image_0000.pgm", "castle model: straight walls, towers"),
]

NORMAL = [  # texture-rich natural, painted and cluttered scenes
    Photo(O, "fruits.jpg", "fruit: smooth shading, specular texture"),
    Photo(O, "graf1.png", "graffiti wall: dense painted texture"),
    Photo(O, "starry_night.jpg", "painting: brush-stroke texture"),
    Photo(S, "astronaut.png", "portrait with flags and a suit: mixed texture"),
    Photo(O, "baboon.jpg", "fur: fine texture"),
    Photo(O, "aero1.jpg", "aerial view of a town: dense small structures"),
    Photo(O, "aloeL.jpg", "aloe plant on a textured backdrop"),
    Photo(O, "rubberwhale1.png", "cluttered toys and fabric"),
    Photo(O, "squirrel_cls.jpg", "squirrel, bark and foliage"),
    Photo(O, "butterfly.jpg", "butterfly on leaves"),
    Photo(O, "chicky_512.png", "dog: fur and carpet"),
    Photo(O, "box_in_scene.png", "cluttered desk with printed boxes"),
    Photo(O, "board.jpg", "printed circuit board: dense components"),
    Photo(S, "chelsea.png", "cat: fur"),
    Photo(S, "coffee.png", "coffee cup on wood grain"),
    Photo(S, "grass.png", "grass: stochastic texture"),
    Photo(S, "gravel.png", "gravel: stochastic texture"),
    Photo(S, "motorcycle_left.png", "motorcycle in a cluttered garage"),
    Photo(V, "Klimt/Klimt.jpeg", "painting (The Kiss): ornament texture"),
    Photo(V, "Solvay/Solvay_conference_1927_Version2_1024x705.jpg",
          "group photograph: faces, suits"),
]

QUICK_IMAGES = 4
QUICK_PLAN = {"p": [10, 30, 60], "alpha": [0.0, 0.8, 0.95], "pairs": 1}
QUICK_FRAMES = 8          # one sequence per video category

VIDEO = [
    # structure + texture: man-made scenes as photographed
    Scene("structure/texture", Photo(O, "building.jpg", "hotel facade and trees")),
    Scene("structure/texture", Photo(O, "leuvenA.jpg", "street of brick houses")),
    Scene("structure/texture", Photo(S, "motorcycle_left.png", "garage with shelves"), blur=True),
    # no structure + texture: natural texture
    Scene("no-structure/texture", Photo(O, "aloeL.jpg", "aloe on a textured backdrop")),
    Scene("no-structure/texture", Photo(S, "gravel.png", "gravel")),
    Scene("no-structure/texture", Photo(O, "starry_night.jpg", "painting"), blur=True),
    # structure, no texture: low-texture photographs, or texture removed
    Scene("structure/no-texture", Photo(O, "ela_original.jpg", "notebook and elastic band")),
    Scene("structure/no-texture", Photo(V, "mbt/cube/image0000.pgm",
                                        "white table, cylinder, cube")),
    Scene("structure/no-texture", Photo(O, "building.jpg", "hotel facade"), flatten=True,
          decay=0.6, blur=True),
    # no structure, no texture: smooth shading only
    Scene("no-structure/no-texture", Photo(O, "apple.jpg", "apple: smooth shading")),
    Scene("no-structure/no-texture", Photo(S, "moon.png", "lunar surface, few faint craters")),
    Scene("no-structure/no-texture", Photo(O, "aloeL.jpg", "aloe, out of focus"), defocus=6.0,
          decay=0.6, blur=True),
]
VIDEO_CATEGORIES = ["structure/texture", "no-structure/texture",
                    "structure/no-texture", "no-structure/no-texture"]
