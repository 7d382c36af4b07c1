#!/usr/bin/env bash
# Self-test of the DragonBones reference checker: runs it (through run.sh, so the pinned runtime
# is installed) on the hand-written fixture/rig_ske.json + rig_tex.json and compares world
# vertices, draw order, colours and events with values worked out by hand from the format's
# definition (docs/dragonbones-format.md). Prints "N passed, M failed"; exit 1 on a failure.
#
# The fixture (frameRate 10 on the armature, so frame k is at k/10 s; the root's 24 is unused):
#   b1 (parent root): x 10, y 20                  -> world matrix: translate (10, 20)
#   b2 (parent b1):  x 100, skX = skY = 90        -> rotation 90 deg (y down: clockwise),
#                     world a=0 b=1 c=-1 d=0 tx=110 ty=20, i.e. (x, y) -> (110 - y, 20 + x)
#   slot skin (root): weighted mesh, slotPose identity, so "vertices" are armature space:
#     v0 (10,10) b1:1   v1 (110,10) b1:.5 b2:.5   v2 (110,30) b2:1   v3 (10,30) b1:1
#     bonePose b1 = translate (10,20); b2 = the matrix above. Bone-local (inverse bonePose):
#     v0 in b1 (0,-10); v1 in b1 (100,-10), in b2: (x,y) -> (y - 20, 110 - x) = (-10, 0);
#     v2 in b2 (10, 0); v3 in b1 (0, 10).
#   slot plate (b2): plateA (0,-5) (20,-5) (20,5) (0,5), plateB (0,0) (10,0) (10,10) (0,10),
#     both unweighted: slot-local, drawn through the slot's (= b2's) world matrix.
#   animation anim, 10 frames = 1 s, played once; linear tweens (tweenEasing 0) from frame 0
#   to the key at frame 10: b1 translate (0,0)->(20,10); b2 rotate 0->270, which the parser
#   takes the short way: 270 - 360 = -90; b2 scale (1,1)->(2,1); plate colour rM 100->0,
#   aM 100->50; ffd skinMesh vertex 1 (offset 2) (0,0)->(0,4); ffd plateA vertex 1 (0,0)->(4,0).
#   plate shows plateA until frame 8, plateB from frame 8; zOrder frame 5 moves slot 0 up 1;
#   event "hit" (ints [7] floats [.5] strings ["boom"]) at frame 3 (0.3 s).
#
# Setup: bones at their bind poses, so skin = its vertices: (10,10) (110,10) (110,30) (10,30);
#   plate v0 (0,-5) -> (110+5, 20+0) = (115,20); v1 (20,-5) -> (115,40).
# t = 0.5 (progress 1/2): b1 = translate (20,25); b2 local: x 100, rotation 90 - 45 = 45 deg,
#   scaleX 1.5 -> world a = 1.5 cos45 = 1.06066, b = 1.06066, c = -sin45 = -0.70711,
#   d = 0.70711, tx = 120, ty = 25.
#   skin deform: vertex 1 offset (0,2) armature space -> b1-local (0,2) (bonePose linear part
#   identity), b2-local R^T (0,2) = (2,0); offsets add to each influence's bone-local position.
#   v0 = (0,-10) + (20,25) = (20,15); v3 = (20,35).
#   v1 = .5 * b1((100,-8)) + .5 * b2((-8,0)) = .5 (120,17) + .5 (120 - 8*1.06066, 25 - 8*1.06066)
#      = .5 (120,17) + .5 (111.51472, 16.51472) = (115.75736, 16.75736).
#   v2 = b2((10,0)) = (120 + 10.6066, 25 + 10.6066) = (130.6066, 35.6066).
#   plate shows plateA, its vertex 1 deformed by (2,0) to (22,-5):
#   v0 (0,-5) -> (120 + 3.53553, 25 - 3.53553) = (123.53553, 21.46447);
#   v1 (22,-5) -> (120 + 23.33452 + 3.53553, 25 + 23.33452 - 3.53553) = (146.87006, 44.79899).
#   colour r = 0.5, a = 0.75. Draw order: plate, skin (the zOrder key at frame 5).
# t = 1.0 (>= the duration: played to the end; the last keys hold): b1 = translate (30,30);
#   b2 rotation 90 - 90 = 0, scale (2,1): world a=2 b=0 c=0 d=1 tx=130 ty=30.
#   skin deform: vertex 1 offset (0,4): b1-local (0,4), b2-local (4,0).
#   v0 = (30,20); v1 = .5 b1((100,-6)) + .5 b2((-6,0)) = .5 (130,24) + .5 (118,30) = (124,27);
#   v2 = b2((10,0)) = (150,30); v3 = (30,40).
#   plate shows plateB: v0 (0,0) -> (130,30); v2 (10,10) -> (150,40). colour r 0, a 0.5.
# t = 0.25: draw order still skin, plate (setup); colour r 0.75, a 0.875.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo '{"times": {"anim": [0.25, 0.5, 1.0]}, "events": {"anim": [[0, 0.25], [0.25, 0.35]]}}' > "$tmp/request.json"
"$here/run.sh" "$here/fixture/rig_ske.json" "$here/fixture/rig_tex.json" "$tmp/request.json" "$tmp/out.json"
node - "$tmp/out.json" <<'JS'
const r = JSON.parse(require("fs").readFileSync(process.argv[2], "utf8"));
let passed = 0, failed = 0;
const check = (what, ok, got) => { if (ok) passed++; else { failed++; console.log(`FAIL ${what}: got ${JSON.stringify(got)}`); } };
const near = (a, b) => Math.abs(a - b) < 1e-3;
const slot = (snap, name) => snap.find((s) => s.name === name);
const vert = (what, snap, name, i, x, y) => {
  const v = slot(snap, name).vertices;
  check(`${what} ${name} vertex ${i} = (${x}, ${y})`, near(v[2 * i], x) && near(v[2 * i + 1], y), [v[2 * i], v[2 * i + 1]]);
};
const [t25, t50, t100] = r.animations.anim.frames.map((f) => f.slots);
check("no lint warnings", r.warnings.length === 0, r.warnings);
check("frameRate is the armature's", r.frameRate === 10, r.frameRate);
check("duration 10 frames / 10 fps", near(r.animations.anim.duration, 1), r.animations.anim.duration);
vert("setup", r.setup, "skin", 1, 110, 10);
vert("setup", r.setup, "plate", 0, 115, 20);
vert("setup", r.setup, "plate", 1, 115, 40);
vert("t=0.5", t50, "skin", 0, 20, 15);
vert("t=0.5", t50, "skin", 1, 115.75736, 16.75736);
vert("t=0.5", t50, "skin", 2, 130.6066, 35.6066);
vert("t=0.5", t50, "plate", 0, 123.53553, 21.46447);
vert("t=0.5", t50, "plate", 1, 146.87006, 44.79899);
vert("t=1", t100, "skin", 0, 30, 20);
vert("t=1", t100, "skin", 1, 124, 27);
vert("t=1", t100, "skin", 2, 150, 30);
vert("t=1", t100, "skin", 3, 30, 40);
vert("t=1", t100, "plate", 0, 130, 30);
vert("t=1", t100, "plate", 2, 150, 40);
check("t=0.5 plate shows plateA", slot(t50, "plate").display === "plateA", slot(t50, "plate").display);
check("t=1 plate shows plateB", slot(t100, "plate").display === "plateB", slot(t100, "plate").display);
check("t=0.25 draw order skin, plate", t25.map((s) => s.name).join() === "skin,plate", t25.map((s) => s.name));
check("t=0.5 draw order plate, skin", t50.map((s) => s.name).join() === "plate,skin", t50.map((s) => s.name));
const c25 = slot(t25, "plate").color, c50 = slot(t50, "plate").color, c100 = slot(t100, "plate").color;
check("t=0.25 plate colour (.75, 1, 1, .875)", near(c25[0], 0.75) && near(c25[3], 0.875), c25);
check("t=0.5 plate colour (.5, 1, 1, .75)", near(c50[0], 0.5) && near(c50[1], 1) && near(c50[3], 0.75), c50);
check("t=1 plate colour (0, 1, 1, .5)", near(c100[0], 0) && near(c100[3], 0.5), c100);
const [e1, e2] = r.events.anim;
check("no event in 0..0.25", e1.filter((e) => e.type === "frameEvent").length === 0, e1);
const hit = e2.filter((e) => e.type === "frameEvent");
check("event hit at 0.3 in 0.25..0.35", hit.length === 1 && hit[0].name === "hit" && near(hit[0].time, 0.3) && hit[0].int === 7
  && near(hit[0].float, 0.5) && hit[0].string === "boom", e2);
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
JS
