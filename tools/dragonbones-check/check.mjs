// Loads a DragonBones export (NAME_ske.json + NAME_tex.json, data version 5.5) in the official
// DragonBonesJS runtime and reports what it draws: per slot in draw order, the display shown,
// its visibility, colour and world vertices, in the setup pose and at requested times of
// animations, plus the events the runtime fires. Also lints the JSON against what the 5.5
// ObjectDataParser reads, so content the runtime would silently ignore or misread shows up as a
// warning.
//
//   node check.mjs NAME_ske.json NAME_tex.json REQUEST.json OUT.json   (or tools/dragonbones-check/run.sh)
//
// The runtime, and who computes what:
// - Core (parser, animation states, timelines, bones, IK/path constraints, slots, z order,
//   deform timelines): npm `@cocos/dragonbones-js` 1.0.2, pinned in package.json: the Cocos fork
//   of DragonBonesJS; its code is DragonBonesJS 5.6.300 (upstream commit 6aaa69a, May 2018).
//   The fork defaults DragonBones.yDown to false (Cocos is y up); we set it back to true, the
//   upstream default, so coordinates are DragonBones' own (y down).
// - Platform (mesh vertices, skinning of weighted meshes, deform offsets applied to them, the
//   display transform, tint/alpha, visibility, child order): the official PixiJS 4 PixiSlot and
//   PixiTextureAtlasData of that same commit, vendored verbatim in vendor/pixi-slot.js (the core
//   leaves Slot._updateMesh/_updateTransform abstract). They run on the minimal PIXI stand-in
//   below (display objects that record what the slot sets; setTransform composes the matrix
//   the way PixiJS 4's TransformStatic does), inside a stand-in armature display (a PIXI
//   Container: its children order is the draw order) that also records dispatched events.
// World vertex = the mesh display's local matrix (from setTransform) applied to
// meshDisplay.vertices; the armature display itself sits at the identity, so these are
// armature-space positions, y down.
//
// REQUEST.json: {"armature": "<name>" (default: the first), "skin": "<name>" (default: the
// default skin), "times": {"<animation>": [t, ...]}, "events": {"<animation>": [[from, to],
// ...]}, "loop": false, "step": 1/60}.
//   times, loop false: the animation played once (playTimes 1). t < duration:
//     animation.gotoAndStopByTime(name, t) (which applies the pose: playConfig runs
//     armature.advanceTime(0)); t >= duration: gotoAndPlayByTime(name, 0, 1) then
//     armature.advanceTime(t) (gotoAndStopByTime would wrap t modulo the duration).
//   times, loop true: gotoAndPlayByTime(name, 0, 0) (loops forever) then advanceTime in steps
//     of `step` seconds (the last one shorter) up to t, so loop-boundary behaviour shows. The
//     runtime sums the steps in floating point: 30 steps of 1/60 land just below 0.5 s, so a
//     key at exactly 0.5 s may not be reached yet (use a step such as 1/64 to avoid that).
//   events: per [from, to]: gotoAndPlayByTime(name, from, loop ? 0 : 1), events of that call
//     discarded, then armature.advanceTime(to - from) (in `step`s when loop); with from null,
//     play(name) and advanceTime(to), the start's events kept (as a game plays it); every event the
//     runtime dispatches in that advance is reported (frameEvent, soundEvent, loopComplete,
//     complete, ...; `type` says which).
// OUT.json: {"version": runtime version, "frameRate": armature frame rate, "setup": Snapshot,
// "animations": {"<name>": {"duration": s, "playTimes": n, "frames": [{"time": t, "slots":
// Snapshot}]}}, "events": {"<name>": [[Event, ...] per step]}, "warnings": [...]}.
// Snapshot = [{"name": slot, "display": display name or null, "displayIndex": n, "visible": bool,
// "color": [r, g, b, a] multipliers, "colorOffset": [r, g, b, a] (Pixi ignores these), "vertices":
// [x0, y0, ...] or null (non-mesh display), "skinned": bool}] in draw order.
// Event = {"name", "type", "time", "int", "float", "string" (the first of each list or null),
// "ints", "floats", "strings", "bone", "slot"}.
// Exit status: 0 when loaded (warnings are reported, not fatal), 2 when the runtime refuses it.
import fs from "node:fs";
import * as core from "@cocos/dragonbones-js";
import { installPixiSlot } from "./vendor/pixi-slot.js";

const [skePath, texPath, requestPath, outPath] = process.argv.slice(2);
if (!outPath) {
  console.error("usage: node check.mjs NAME_ske.json NAME_tex.json REQUEST.json OUT.json");
  process.exit(2);
}
const raw = JSON.parse(fs.readFileSync(skePath, "utf8"));
const rawTex = JSON.parse(fs.readFileSync(texPath, "utf8"));
const request = JSON.parse(fs.readFileSync(requestPath, "utf8"));
const STEP = request.step || 1 / 60;

// ---- A minimal PIXI (v4) stand-in: just what PixiSlot/PixiTextureAtlasData touch. ----
class DisplayObject {
  constructor() {
    this.parent = null;
    this.visible = true;
    this.alpha = 1;
    this.x = 0; this.y = 0; this.rotation = 0;
    this.scaleX = 1; this.scaleY = 1; this.skewX = 0; this.skewY = 0; this.pivotX = 0; this.pivotY = 0;
    const self = this;
    this.position = { set(x, y) { self.x = x; self.y = y; } };
    this.scale = { set(x, y) { self.scaleX = x; self.scaleY = y; } };
    this.skew = { set(x, y) { self.skewX = x; self.skewY = y; } };
  }
  setTransform(x = 0, y = 0, scaleX = 1, scaleY = 1, rotation = 0, skewX = 0, skewY = 0, pivotX = 0, pivotY = 0) {
    Object.assign(this, { x, y, scaleX, scaleY, rotation, skewX, skewY, pivotX, pivotY });
    return this;
  }
  // PixiJS 4 TransformStatic.updateLocalTransform (with updateSkew): the matrix Pixi draws with.
  localMatrix() {
    const a = Math.cos(this.rotation + this.skewY) * this.scaleX;
    const b = Math.sin(this.rotation + this.skewY) * this.scaleX;
    const c = -Math.sin(this.rotation - this.skewX) * this.scaleY;
    const d = Math.cos(this.rotation - this.skewX) * this.scaleY;
    return { a, b, c, d, tx: this.x - (this.pivotX * a + this.pivotY * c), ty: this.y - (this.pivotX * b + this.pivotY * d) };
  }
  destroy() {}
}
class Container extends DisplayObject {
  constructor() { super(); this.children = []; }
  addChild(child) { return this.addChildAt(child, this.children.length); }
  addChildAt(child, index) {
    if (child.parent) child.parent.removeChild(child);
    if (index < 0 || index > this.children.length) throw new Error(`addChildAt: index ${index} out of bounds`);
    child.parent = this;
    this.children.splice(index, 0, child);
    return child;
  }
  removeChild(child) {
    const i = this.children.indexOf(child);
    if (i >= 0) { this.children.splice(i, 1); child.parent = null; }
    return child;
  }
  getChildIndex(child) { return this.children.indexOf(child); }
  swapChildren(a, b) {
    if (a === b) return;
    const i = this.children.indexOf(a), j = this.children.indexOf(b);
    this.children[i] = b; this.children[j] = a;
  }
}
class Sprite extends Container {
  constructor(texture = null) { super(); this.texture = texture; this.tint = 0xffffff; this.blendMode = 0; }
}
class Mesh extends Container {
  constructor() { super(); this.texture = null; this.vertices = null; this.uvs = null; this.indices = null; this.tint = 0xffffff; this.dirty = 0; this.indexDirty = 0; }
}
class Texture {
  constructor(baseTexture, frame, orig, trim, rotate) { Object.assign(this, { baseTexture, frame, orig, trim, rotate }); this.width = frame ? frame.width : 0; this.height = frame ? frame.height : 0; }
  destroy() {}
}
class Rectangle { constructor(x, y, width, height) { Object.assign(this, { x, y, width, height }); } }
const PIXI = {
  VERSION: "4.8.9", Container, Sprite, Texture, Rectangle,
  mesh: { Mesh: Object.assign(Mesh, { DRAW_MODES: { TRIANGLE_MESH: 0, TRIANGLES: 1 } }) },
  BLEND_MODES: { NORMAL: 0, ADD: 1, MULTIPLY: 2, SCREEN: 3, OVERLAY: 4, DARKEN: 5, LIGHTEN: 6, COLOR_DODGE: 7, COLOR_BURN: 8, HARD_LIGHT: 9, SOFT_LIGHT: 10, DIFFERENCE: 11 },
};

// ---- The runtime: the core's classes plus the vendored Pixi platform classes. ----
const db = installPixiSlot({ ...core }, PIXI);
db.DragonBones.yDown = true; // upstream default; the Cocos fork sets false (see above)

// The armature display proxy (what PixiArmatureDisplay is, minus drawing): a Container whose
// children the slots order, and the event dispatcher of the armature.
class ArmatureDisplay extends Container {
  constructor() { super(); this._armature = null; this.events = []; }
  dbInit(armature) { this._armature = armature; }
  dbClear() { this._armature = null; }
  dbUpdate() {}
  dispose() { if (this._armature) { this._armature.dispose(); this._armature = null; } }
  destroy() { this.dispose(); }
  // The runtime buffers an event only when a listener exists: listen to everything.
  hasDBEventListener() { return true; }
  // EventObjects go back to the pool after dispatch: copy what they carry now.
  dispatchDBEvent(type, e) {
    const data = e.data;
    const list = (k) => (data && data[k] ? Array.from(data[k]) : []);
    const ints = list("ints"), floats = list("floats"), strings = list("strings");
    this.events.push({
      name: e.name || null, type, time: e.time, int: ints.length ? ints[0] : null, float: floats.length ? floats[0] : null,
      string: strings.length ? strings[0] : null, ints, floats, strings, bone: e.bone ? e.bone.name : null, slot: e.slot ? e.slot.name : null,
    });
  }
  addDBEventListener() {}
  removeDBEventListener() {}
  get armature() { return this._armature; }
  get animation() { return this._armature.animation; }
}

// A BaseFactory as PixiFactory builds (PixiFactory itself needs PIXI's ticker and renderer).
const quiet = console.info;
console.info = () => {}; // the runtime's banner (DragonBones constructor)
const dragonBonesInstance = new db.DragonBones(new ArmatureDisplay());
console.info = quiet;
function Factory() { db.BaseFactory.call(this, null); this._dragonBones = dragonBonesInstance; }
Factory.prototype = Object.create(db.BaseFactory.prototype);
Factory.prototype.constructor = Factory;
Factory.prototype._buildTextureAtlasData = function (textureAtlasData, textureAtlas) {
  if (textureAtlasData) textureAtlasData.renderTexture = textureAtlas;
  else textureAtlasData = db.BaseObject.borrowObject(db.PixiTextureAtlasData);
  return textureAtlasData;
};
Factory.prototype._buildArmature = function (dataPackage) {
  const armature = db.BaseObject.borrowObject(db.Armature);
  const display = new ArmatureDisplay();
  armature.init(dataPackage.armature, display, display, this._dragonBones);
  return armature;
};
Factory.prototype._buildSlot = function (dataPackage, slotData, armature) {
  const slot = db.BaseObject.borrowObject(db.PixiSlot);
  slot.init(slotData, armature, new PIXI.Sprite(), new PIXI.mesh.Mesh(null, null, null, null, PIXI.mesh.Mesh.DRAW_MODES.TRIANGLES));
  return slot;
};

const warnings = lint(raw, rawTex);
const factory = new Factory();
let data = null;
let armature = null;
const armatureName = request.armature || ((raw.armature || [])[0] || {}).name;
const skinName = request.skin || "";
try {
  data = factory.parseDragonBonesData(raw, "sinew");
  if (!data) throw new Error(`data version '${raw.version}' not supported (compatibleVersion '${raw.compatibleVersion}')`);
  // The "base texture" the atlas's sub-textures are cut from: only its size matters here.
  factory.parseTextureAtlasData(rawTex, { width: rawTex.width || 0, height: rawTex.height || 0 }, "sinew");
  armature = factory.buildArmature(armatureName, "sinew", skinName);
  if (!armature) throw new Error(`could not build armature '${armatureName}' (skin '${skinName}')`);
} catch (e) {
  console.error(`DragonBonesJS refused ${skePath}: ${e.message}`);
  process.exit(2);
}
let display = armature.display;
const animations = armature.armatureData.animations;

// What Pixi would draw now: the container's children in order.
function snapshot() {
  const bySlotDisplay = new Map(armature.getSlots().map((s) => [s._renderDisplay, s]));
  return display.children.map((child) => {
    const slot = bySlotDisplay.get(child);
    if (!slot) return { name: null, display: null, visible: child.visible, color: null, vertices: null };
    const ct = slot._colorTransform;
    const shown = slot._display !== null && child.texture !== null;
    const entry = {
      name: slot.name,
      display: slot._displayData ? slot._displayData.name : null,
      displayIndex: slot.displayIndex,
      visible: Boolean(child.visible && shown),
      color: [ct.redMultiplier, ct.greenMultiplier, ct.blueMultiplier, ct.alphaMultiplier],
      colorOffset: [ct.redOffset, ct.greenOffset, ct.blueOffset, ct.alphaOffset],
      vertices: null,
      skinned: false,
    };
    if (child instanceof Mesh && child === slot._meshDisplay && child.vertices) {
      const m = child.localMatrix();
      const v = child.vertices;
      const out = new Array(v.length);
      for (let i = 0; i < v.length; i += 2) {
        out[i] = m.a * v[i] + m.c * v[i + 1] + m.tx;
        out[i + 1] = m.b * v[i] + m.d * v[i + 1] + m.ty;
      }
      entry.vertices = out;
      const vd = slot._deformVertices && slot._deformVertices.verticesData;
      entry.skinned = Boolean(vd && vd.weight);
    }
    return entry;
  });
}

// Advance the armature by `seconds` (in STEP pieces when stepped) and flush buffered events.
function advance(seconds, stepped) {
  if (!stepped) armature.advanceTime(seconds);
  else {
    let done = 0;
    while (seconds - done > 1e-9) {
      const dt = Math.min(STEP, seconds - done);
      armature.advanceTime(dt);
      done += dt;
    }
  }
  dragonBonesInstance.advanceTime(0); // dispatches the events the step buffered
}
function findAnimation(name) {
  if (!(name in animations)) {
    console.error(`no animation '${name}' in armature '${armatureName}' of ${skePath}`);
    process.exit(2);
  }
  return animations[name];
}
// A fresh armature in its setup pose for every time and event step, as a game that builds one
// and plays the animation would have it (nothing carried over from an earlier request).
function resetToSetup() {
  armature.dispose();
  armature = factory.buildArmature(armatureName, "sinew", skinName);
  display = armature.display;
  armature.advanceTime(0);
  dragonBonesInstance.advanceTime(0);
  display.events.length = 0;
}

armature.advanceTime(0);
dragonBonesInstance.advanceTime(0);
display.events.length = 0;
const result = { version: db.DragonBones.VERSION + " (@cocos/dragonbones-js 1.0.2) + PixiSlot 6aaa69a", frameRate: armature.armatureData.frameRate, setup: snapshot(), animations: {}, events: {}, warnings };

const loop = Boolean(request.loop);
for (const [name, times] of Object.entries(request.times || {})) {
  const data = findAnimation(name);
  const frames = times.map((time) => {
    resetToSetup();
    if (loop) {
      armature.animation.gotoAndPlayByTime(name, 0, 0);
      advance(time, true);
    } else if (time < data.duration) {
      armature.animation.gotoAndStopByTime(name, time);
      dragonBonesInstance.advanceTime(0);
    } else {
      armature.animation.gotoAndPlayByTime(name, 0, 1);
      advance(time, false);
    }
    display.events.length = 0;
    return { time, slots: snapshot() };
  });
  result.animations[name] = { duration: data.duration, playTimes: data.playTimes, frames };
}
for (const [name, steps] of Object.entries(request.events || {})) {
  findAnimation(name);
  result.events[name] = steps.map(([from, to]) => {
    resetToSetup();
    if (from === null) {
      // From the start as a game plays it: the events of the first frame count too.
      armature.animation.play(name, loop ? 0 : 1);
      advance(to, loop);
      const fired = display.events.slice();
      display.events.length = 0;
      return fired;
    }
    armature.animation.gotoAndPlayByTime(name, from, loop ? 0 : 1);
    dragonBonesInstance.advanceTime(0);
    display.events.length = 0;
    advance(to - from, loop);
    const fired = display.events.slice();
    display.events.length = 0;
    return fired;
  });
}
fs.writeFileSync(outPath, JSON.stringify(result));

// What ObjectDataParser (DataParser.DATA_VERSION 5.5) reads; anything else it ignores without a
// word. Covers the objects sinew writes (bones, slots, image/mesh displays, bone/slot/ffd/zOrder
// timelines, frame events) and names the others.
function lint(json, tex) {
  const out = [];
  const only = (where, obj, keys) => {
    for (const k of Object.keys(obj || {})) if (!keys.includes(k)) out.push(`${where}: key '${k}' is not read by the 5.5 parser`);
  };
  const whole = (where, v) => {
    if (v !== undefined && !Number.isInteger(v)) out.push(`${where}: ${v} is not a whole number of frames`);
  };
  const TRANSFORM = ["x", "y", "skX", "skY", "scX", "scY", "rotate", "skew"];
  const COLOR = ["aM", "rM", "gM", "bM", "aO", "rO", "gO", "bO"];
  const EVENT = ["name", "type", "gotoAndPlay", "bone", "slot", "ints", "floats", "strings"];
  const colorOk = (where, c) => {
    only(where, c, COLOR);
    for (const k of ["aM", "rM", "gM", "bM"]) {
      if (c && c[k] !== undefined && !Number.isInteger(c[k])) out.push(`${where}: ${k} ${c[k]} is stored as a whole percent (Math.round)`);
    }
  };
  if (!["4.0", "4.5", "5.0", "5.5"].includes(json.version) && !["4.0", "4.5", "5.0", "5.5"].includes(json.compatibleVersion)) {
    out.push(`top level: version '${json.version}' / compatibleVersion '${json.compatibleVersion}' is not one the parser accepts`);
  }
  only("top level", json, ["version", "compatibleVersion", "name", "frameRate", "armature", "stage", "textureAtlas", "isGlobal", "userData"]);
  if (json.isGlobal !== undefined) out.push("top level: 'isGlobal' is not read (5.5 data is always local)");
  only("texture atlas", tex, ["name", "imagePath", "width", "height", "scale", "format", "SubTexture", "userData"]);
  const regions = new Map();
  for (const t of tex.SubTexture || []) {
    only(`SubTexture ${t.name}`, t, ["name", "x", "y", "width", "height", "rotated", "frameX", "frameY", "frameWidth", "frameHeight"]);
    regions.set(t.name, t);
  }
  for (const arm of json.armature || []) {
    const A = `armature ${arm.name}`;
    const fps = arm.frameRate || json.frameRate || 24;
    only(A, arm, ["name", "type", "frameRate", "canvas", "aabb", "bone", "ik", "slot", "skin", "path", "animation", "defaultActions", "actions", "userData"]);
    const bones = arm.bone || [];
    const boneNames = bones.map((b) => b.name);
    const seen = new Set();
    for (const b of bones) {
      only(`${A}, bone ${b.name}`, b, ["name", "parent", "type", "length", "transform", "inheritTranslation", "inheritRotation", "inheritScale", "inheritReflection", "segmentX", "segmentY", "vertices", "userData"]);
      only(`${A}, bone ${b.name}, transform`, b.transform, TRANSFORM);
      if (b.transform && ("rotate" in b.transform || "skew" in b.transform) && ("skX" in b.transform || "skY" in b.transform)) out.push(`${A}, bone ${b.name}: transform has rotate/skew and skX/skY: skX/skY are ignored`);
      if (b.parent !== undefined && !boneNames.includes(b.parent)) out.push(`${A}, bone ${b.name}: unknown parent ${b.parent}`);
      if (seen.has(b.name)) out.push(`${A}, bone ${b.name}: listed twice`);
      seen.add(b.name);
    }
    for (const k of arm.ik || []) {
      only(`${A}, ik ${k.name}`, k, ["name", "bone", "target", "chain", "bendPositive", "scale", "weight", "userData"]);
      if (!boneNames.includes(k.bone) || !boneNames.includes(k.target)) out.push(`${A}, ik ${k.name}: unknown bone or target (the constraint is dropped)`);
    }
    const slots = arm.slot || [];
    const slotNames = slots.map((s) => s.name);
    for (const s of slots) {
      only(`${A}, slot ${s.name}`, s, ["name", "parent", "displayIndex", "blendMode", "color", "actions", "userData"]);
      if (!boneNames.includes(s.parent)) out.push(`${A}, slot ${s.name}: unknown parent bone ${s.parent}`);
      if (s.color) colorOk(`${A}, slot ${s.name}, color`, s.color);
    }
    const meshes = new Map(); // "skin/slot/display" -> raw mesh
    for (const skin of arm.skin || []) {
      const S = `${A}, skin ${skin.name || "default"}`;
      only(S, skin, ["name", "slot", "userData"]);
      for (const ss of skin.slot || []) {
        only(`${S}, slot ${ss.name}`, ss, ["name", "display", "userData"]);
        if (!slotNames.includes(ss.name)) out.push(`${S}: unknown slot ${ss.name} (its displays are dropped)`);
        for (const d of ss.display || []) {
          if (!d) continue;
          const D = `${S}, slot ${ss.name}, display ${d.name}`;
          const type = d.type || "image";
          const common = ["name", "type", "path", "transform", "userData"];
          if (type === "image") only(D, d, [...common, "pivot"]);
          else if (type === "mesh") only(D, d, [...common, "share", "skin", "inheritDeform", "vertices", "uvs", "triangles", "weights", "slotPose", "bonePose", "edges", "userEdges", "width", "height", "glueWeights", "glueMeshes"]);
          else { out.push(`${D}: type '${type}' (sinew writes image and mesh displays only)`); continue; }
          only(`${D}, transform`, d.transform, TRANSFORM);
          const region = d.path || d.name;
          if (!regions.has(region)) out.push(`${D}: texture '${region}' is not in the atlas`);
          if (type !== "mesh" || d.share) continue;
          meshes.set(`${skin.name || "default"}/${ss.name}/${d.name}`, d);
          const n = d.vertices.length / 2;
          if (d.uvs.length !== d.vertices.length) out.push(`${D}: ${d.uvs.length / 2} uvs for ${n} vertices`);
          if (n > 32767) out.push(`${D}: ${n} vertices: the vertex count is stored in an Int16Array`);
          if (d.triangles.some((i) => !(i >= 0 && i < n))) out.push(`${D}: triangle index out of range`);
          if (d.weights) {
            if (!d.slotPose || d.slotPose.length !== 6) out.push(`${D}: weighted mesh without a 6-number slotPose`);
            if (!d.bonePose || d.bonePose.length % 7 !== 0) out.push(`${D}: bonePose is not [boneIndex, a, b, c, d, tx, ty] * n`);
            const poseBones = [];
            for (let i = 0; i < (d.bonePose || []).length; i += 7) {
              poseBones.push(d.bonePose[i]);
              if (!(d.bonePose[i] >= 0 && d.bonePose[i] < bones.length)) out.push(`${D}: bonePose names bone index ${d.bonePose[i]}`);
            }
            let i = 0, count = 0;
            while (i < d.weights.length) {
              const k = d.weights[i++];
              let sum = 0;
              for (let j = 0; j < k; j++, i += 2) {
                if (!poseBones.includes(d.weights[i])) out.push(`${D}: vertex ${count} weights bone index ${d.weights[i]}, which has no bonePose entry`);
                sum += d.weights[i + 1];
              }
              if (Math.abs(sum - 1) > 1e-4) out.push(`${D}: vertex ${count} weights sum to ${sum}`);
              count++;
            }
            if (count !== n) out.push(`${D}: ${count} weighted vertices but ${n} vertices`);
          }
        }
      }
    }
    const duration = (a) => Math.max(a.duration === undefined ? 1 : a.duration, 1);
    for (const an of arm.animation || []) {
      const N = `${A}, animation ${an.name}`;
      only(N, an, ["name", "duration", "playTimes", "fadeInTime", "scale", "frame", "zOrder", "bone", "surface", "slot", "ffd", "ik", "animation", "userData"]);
      whole(`${N}, duration`, an.duration);
      const total = duration(an);
      // Frames: `duration` in frames (default 1); key k starts at the sum of the durations before
      // it, keys starting at or after the animation's end are never read.
      const frames = (where, list, fields, tween) => {
        let start = 0;
        (list || []).forEach((f, i) => {
          const W = `${where} frame ${i}`;
          only(W, f, ["duration", ...(tween ? ["tweenEasing", "curve"] : []), ...fields]);
          whole(`${W}, duration`, f.duration);
          const d = f.duration === undefined ? 1 : f.duration;
          const last = i === list.length - 1;
          if (d === 0 && !last) out.push(`${W}: duration 0 before the last frame: the parser still gives it one frame, later frames shift`);
          if (start >= total && start > 0 && !(last && start === total)) out.push(`${W}: starts at frame ${start}, at or after the animation's ${total} frames (never read)`);
          if (tween && !last && !("tweenEasing" in f) && !("curve" in f)) out.push(`${W}: no tweenEasing: holds its value until the next frame (stepped)`);
          if (tween && "tweenEasing" in f && f.tweenEasing !== null && "curve" in f) out.push(`${W}: both curve and tweenEasing: the curve wins`);
          start += d;
        });
      };
      const events = [];
      (an.frame || []).forEach((f, i) => {
        only(`${N}, frame ${i}`, f, ["duration", "event", "sound", "action", "events", "actions"]);
        for (const e of f.events || []) { only(`${N}, frame ${i}, event`, e, EVENT); events.push(e); }
      });
      frames(`${N}, action`, an.frame, ["event", "sound", "action", "events", "actions"], false);
      if (an.zOrder) {
        only(`${N}, zOrder`, an.zOrder, ["frame", "scale", "offset"]);
        frames(`${N}, zOrder`, an.zOrder.frame, ["zOrder"], false);
        (an.zOrder.frame || []).forEach((f, i) => {
          const z = f.zOrder || [];
          let prev = -1;
          for (let k = 0; k < z.length; k += 2) {
            if (!(z[k] > prev)) out.push(`${N}, zOrder frame ${i}: slot indices not increasing`);
            prev = z[k];
            if (!(z[k] + z[k + 1] >= 0 && z[k] + z[k + 1] < slots.length)) out.push(`${N}, zOrder frame ${i}: slot ${z[k]} moved to ${z[k] + z[k + 1]}, outside 0..${slots.length - 1}`);
          }
        });
      }
      for (const t of an.bone || []) {
        const B = `${N}, bone ${t.name}`;
        only(B, t, ["name", "scale", "offset", "frame", "translateFrame", "rotateFrame", "scaleFrame"]);
        if (!boneNames.includes(t.name)) out.push(`${B}: unknown bone (timeline dropped)`);
        if (t.frame) out.push(`${B}: 'frame' (the 4.5-style all-in-one bone timeline) is read, but sinew writes translate/rotate/scale frames`);
        if (t.translateFrame) frames(`${B}, translateFrame`, t.translateFrame, ["x", "y"], true);
        if (t.rotateFrame) frames(`${B}, rotateFrame`, t.rotateFrame, ["rotate", "skew", "clockwise"], true);
        if (t.scaleFrame) frames(`${B}, scaleFrame`, t.scaleFrame, ["x", "y"], true);
      }
      for (const t of an.slot || []) {
        const S = `${N}, slot ${t.name}`;
        only(S, t, ["name", "scale", "offset", "frame", "displayFrame", "colorFrame"]);
        if (!slotNames.includes(t.name)) out.push(`${S}: unknown slot (timeline dropped)`);
        if (t.displayFrame) frames(`${S}, displayFrame`, t.displayFrame, ["value", "displayIndex", "event", "sound", "action", "events", "actions"], false);
        if (t.colorFrame) {
          frames(`${S}, colorFrame`, t.colorFrame, ["value", "color"], true);
          t.colorFrame.forEach((f, i) => colorOk(`${S}, colorFrame ${i}, value`, f.value || f.color));
        }
      }
      for (const t of an.ffd || []) {
        const F = `${N}, ffd ${t.slot}/${t.name}`;
        only(F, t, ["name", "slot", "skin", "scale", "offset", "frame"]);
        const mesh = meshes.get(`${t.skin || "default"}/${t.slot}/${t.name}`);
        if (!mesh) { out.push(`${F}: no such mesh in skin '${t.skin || "default"}' (timeline dropped)`); continue; }
        frames(`${F}`, t.frame, ["vertices", "offset"], true);
        (t.frame || []).forEach((f, i) => {
          if ((f.offset || 0) + (f.vertices || []).length > mesh.vertices.length) out.push(`${F} frame ${i}: offset ${f.offset || 0} + ${(f.vertices || []).length} numbers for ${mesh.vertices.length / 2} vertices (the rest is dropped)`);
        });
      }
      for (const k of ["surface", "ik", "animation"]) if (an[k]) out.push(`${N}: '${k}' timelines (sinew does not write them)`);
    }
    if (fps <= 0) out.push(`${A}: frameRate ${fps}`);
  }
  return out;
}
