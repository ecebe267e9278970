#!/usr/bin/env bash
# Writes reference outputs of the tools and the Python module to OUT (timings stripped), to
# compare two builds byte for byte around a change that should not change results:
#   bash scripts/reference_outputs.sh build /tmp/ref_after && diff -r /tmp/ref_before /tmp/ref_after
# facyl_fit variants (methods, priors, inliers, no cylinder, a bad option), facyl_detect on the
# bundled scene and a simulated cluttered one, the help texts, and Python fit_cylinders/detect.
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: scripts/reference_outputs.sh BUILD OUT" >&2; exit 2; }
root=$(cd "$(dirname "$0")/.." && pwd)
B=$(cd "$1" && pwd); mkdir -p "$2"; O=$(cd "$2" && pwd)
T=/tmp/facyl_reference_work # a fixed folder: file names in the outputs stay the same
rm -rf "$T"; mkdir -p "$T"; cd "$T"
notime() { sed 's/"timing_ms":{[^}]*}//'; }
"$B/apps/facyl_simulate" --radius 0.04 --lids 1 --noise 0.02 --seed 5 --random-axis c1.pcd > "$O/simulate_c1.json"
"$B/apps/facyl_simulate" --radius 0.06 --occlusion 0.5 --noise 0.05 --seed 9 --with-normals c2.pcd > "$O/simulate_c2.json"
"$B/apps/facyl_synth" --layout cluttered --seed 7 clutter > "$O/synth.json" 2>/dev/null
"$B/apps/facyl_fit" c1.pcd c2.pcd 2>&1 | notime > "$O/fit_default.json"
"$B/apps/facyl_fit" --inliers --max-cylinders 2 c1.pcd 2>&1 | notime > "$O/fit_inliers.json"
"$B/apps/facyl_fit" --method pcl-ransac c1.pcd c2.pcd 2>&1 | notime > "$O/fit_ransac.json"
"$B/apps/facyl_fit" --up 0,0,1 --orientations 900 --accumulators 3 --seed 4 c1.pcd 2>&1 | notime > "$O/fit_prior.json"
"$B/apps/facyl_fit" --radius-limits auto --voting rabbani c2.pcd 2>&1 | notime > "$O/fit_rabbani.json"
"$B/apps/facyl_fit" --radius-limits 0.3,0.5 c2.pcd 2>&1 | notime > "$O/fit_none.json"
{ "$B/apps/facyl_fit" --orientations 5 c1.pcd 2>&1 && echo "exit 0" || echo "exit $?"; } > "$O/fit_bad.txt"
"$B/apps/facyl_fit" -h > "$O/fit_help.txt" 2>&1
"$B/apps/facyl_detect" -h > "$O/detect_help.txt" 2>&1
"$B/apps/facyl_simulate" -h > "$O/simulate_help.txt" 2>&1
"$B/apps/facyl_detect" "$root/data/default_scene.pcd" | notime > "$O/detect_default.json"
"$B/apps/facyl_detect" clutter.pcd | notime > "$O/detect_clutter.json"
"$B/apps/facyl_detect" --orientations 200 --seed 3 --prior uniform clutter.pcd | notime > "$O/detect_options.json"
"$B/apps/facyl_detect" --track clutter.pcd clutter.pcd | notime > "$O/detect_track.json"
PYTHONPATH="$B/python" /usr/bin/python3 - > "$O/python.txt" 2>&1 <<'PY'
import facyl
s = facyl.simulate_cylinder(radius=0.05, height=0.3, base=(0, 0, 0), random_axis=True,
                            lid_ratio=1.0, noise=0.02, seed=4)
for c in facyl.fit_cylinders(s["points"]): print(c.as_dict())
for c in facyl.fit_cylinders(s["points"], s["normals"], orientations=900, seed=2): print(c.as_dict())
f = facyl.render_tabletop_scene(seed=3, layout="cluttered")
r = facyl.detect(f["points"], f["colors"], camera=f["camera"])
r.pop("timing_ms", None)
for o in r["objects"]: o.pop("indices", None)
print(r)
PY
rm -rf "$T"
echo "reference_outputs: $(ls "$O" | wc -l) files in $O"
