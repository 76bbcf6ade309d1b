# Photometric refinement through the CLI (sourced by tests/run.sh: ok/fail, $tmp, $BUILD, $RUNNER):
# on by default ("refined":true and a "refine" time), --no-refine keeps HOME's estimate, and the
# refined H is within 0.1 px of the truth on a structured pair and never worse than HOME's.
reg_refine="$RUNNER $BUILD/bin/home-register"
if $RUNNER "$BUILD/bin/home-make-pair" --p 20 --seed 11 "$tmp/refine_a.pgm" "$tmp/refine_b.pgm" > "$tmp/refine_truth.json" &&
   $reg_refine "$tmp/refine_a.pgm" "$tmp/refine_b.pgm" > "$tmp/refine_on.json" &&
   $reg_refine --no-refine "$tmp/refine_a.pgm" "$tmp/refine_b.pgm" > "$tmp/refine_off.json" &&
   python3 - "$tmp/refine_truth.json" "$tmp/refine_on.json" "$tmp/refine_off.json" <<'PY'
import json, sys
truth = json.load(open(sys.argv[1]))["H"]
on, off = (json.loads(open(p).read().strip().splitlines()[-1]) for p in sys.argv[2:4])
assert on["refined"] is True and off["refined"] is False, (on.get("refined"), off.get("refined"))
assert "refine" in on["ms"] and on["ms"]["refine"] >= 0
def err(h):
    e = 0
    for x, y in ((0, 0), (639, 0), (0, 359), (639, 359)):
        w1 = h[6] * x + h[7] * y + h[8]; w2 = truth[6] * x + truth[7] * y + truth[8]
        dx = (h[0] * x + h[1] * y + h[2]) / w1 - (truth[0] * x + truth[1] * y + truth[2]) / w2
        dy = (h[3] * x + h[4] * y + h[5]) / w1 - (truth[3] * x + truth[4] * y + truth[5]) / w2
        e += (dx * dx + dy * dy) ** 0.5 / 4
    return e
assert err(on["H"]) < 0.1, err(on["H"])
assert err(on["H"]) <= err(off["H"]) + 0.05, (err(on["H"]), err(off["H"]))
PY
then ok cli_refine; else fail cli_refine "$(head -c 300 "$tmp/refine_on.json" "$tmp/refine_off.json")"; fi
