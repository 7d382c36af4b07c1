// Loads a Spine export in the official runtime (@esotericsoftware/spine-core, pinned in
// package.json: 4.2.119, and 4.3.13 as `spine-core-43` for files whose `skeleton.spine` says
// 4.3) and reports what it draws: per slot in draw order, its attachment, colour and
// world vertices, in the setup pose and at requested times of animations. Also lints the JSON
// against what the loader of the file's line reads, so content the runtime would silently
// ignore or misread shows up as a warning.
//
//   node check.mjs SKELETON.json SKELETON.atlas REQUEST.json OUT.json
//
// REQUEST.json: {"times": {"<animation>": [t, ...]}, "events": {"<animation>": [[lastTime,
// time, loop], ...]}, "skins": ["<skin>", ...]} (skins combined in order; none: the default). OUT.json: {"setup": Snapshot,
// "animations": {"<name>": {"duration": d, "frames": [{"time": t, "slots": Snapshot}]}},
// "events": {"<name>": [[Event, ...] per step]}, "warnings": [...]}; Event = {"name", "time",
// "int", "float", "string", "audio": null or {"path", "volume", "balance"}}: what Animation.apply fires moving
// from lastTime to time; Snapshot = [{"name", "attachment", "color": [r, g, b, a],
// "vertices": [x0, y0, ...]}] in draw order (vertices only for meshes).
// Exit status: 0 when loaded (warnings are reported, not fatal), 2 when the runtime refuses it.
import fs from "node:fs";

const [skeletonPath, atlasPath, requestPath, outPath] = process.argv.slice(2);
if (!outPath) {
  console.error("usage: node check.mjs SKELETON.json SKELETON.atlas REQUEST.json OUT.json");
  process.exit(2);
}

const raw = JSON.parse(fs.readFileSync(skeletonPath, "utf8"));
// 4.3 moved pose data into pose objects and constraints into one typed array (spine-format.md
// §10, §11); everything this script touches differs only in the calls below.
const v43 = String((raw.skeleton || {}).spine || "").startsWith("4.3.");
const spine = await import(v43 ? "spine-core-43" : "@esotericsoftware/spine-core");
const atlas = new spine.TextureAtlas(fs.readFileSync(atlasPath, "utf8"));
const request = JSON.parse(fs.readFileSync(requestPath, "utf8"));
const warnings = lint(raw, atlas);

let data;
try {
  data = new spine.SkeletonJson(new spine.AtlasAttachmentLoader(atlas)).readSkeletonData(raw);
} catch (e) {
  console.error(`spine-core refused ${skeletonPath}: ${e.message}`);
  process.exit(2);
}
// Skins combined in order (a later one overrides an earlier one on a slot), as a game does.
function makeSkeleton() {
  const made = new spine.Skeleton(data);
  if ((request.skins || []).length > 0) {
    const combined = new spine.Skin("combined");
    for (const name of request.skins) {
      const skin = data.findSkin(name);
      if (!skin) {
        console.error(`no skin '${name}' in ${skeletonPath}`);
        process.exit(2);
      }
      combined.addSkin(skin);
    }
    made.setSkin(combined);
  }
  return made;
}
let skeleton = makeSkeleton();

// `physics` false: the world transforms as the last update left them (physics applied).
function snapshot(update = true) {
  if (update) skeleton.updateWorldTransform(spine.Physics.none);
  const order = v43 ? skeleton.drawOrder.appliedPose : skeleton.drawOrder;
  return order.map((slot) => {
    const a = v43 ? slot.appliedPose.getAttachment() : slot.getAttachment();
    const c = v43 ? slot.appliedPose.color : slot.color;
    const entry = { name: slot.data.name, attachment: a ? a.name : null, color: [c.r, c.g, c.b, c.a] };
    if (a instanceof spine.MeshAttachment) {
      const out = new Array(a.worldVerticesLength);
      if (v43) a.computeWorldVertices(skeleton, slot, 0, a.worldVerticesLength, out, 0, 2);
      else a.computeWorldVertices(slot, 0, a.worldVerticesLength, out, 0, 2);
      entry.vertices = out;
    }
    return entry;
  });
}

const setupPose = () => (v43 ? skeleton.setupPose() : skeleton.setToSetupPose());
// Physics constraints (4.2): history matters, so a time is played as a game plays it: a fresh
// skeleton updated at UPDATE_HZ from time 0 (skeleton.update(1 / UPDATE_HZ) between updates,
// Physics.update at each, the animation applied at k / UPDATE_HZ), then, for a time between
// updates, the animation at that time posed with Physics.pose (sinew's scene::physics).
const UPDATE_HZ = 60;
const hasPhysics = !v43 && (data.physicsConstraints || []).length > 0;
function simulated(applyAt, time) {
  skeleton = makeSkeleton();
  const step = 1 / UPDATE_HZ;
  const whole = Math.max(Math.floor(time / step + 1e-9), 0);
  for (let k = 0; k <= whole; k++) {
    applyAt(k * step);
    if (k > 0) skeleton.update(step);
    skeleton.updateWorldTransform(spine.Physics.update);
  }
  if (!(time - whole * step <= 1e-9 * step)) {
    applyAt(time);
    skeleton.updateWorldTransform(spine.Physics.pose);
  }
  const out = snapshot(false);
  skeleton = makeSkeleton();
  return out;
}
setupPose();
const result = { setup: snapshot(), animations: {}, warnings };
for (const [name, times] of Object.entries(request.times || {})) {
  const animation = data.findAnimation(name);
  if (!animation) {
    console.error(`no animation '${name}' in ${skeletonPath}`);
    process.exit(2);
  }
  const applyAt = (time) => {
    setupPose();
    if (v43) animation.apply(skeleton, time, time, false, [], 1, spine.MixFrom.setup, false, false, false);
    else animation.apply(skeleton, time, time, false, [], 1, spine.MixBlend.setup, spine.MixDirection.mixIn);
  };
  const frames = times.map((time) => {
    if (hasPhysics) return { time, slots: simulated(applyAt, time) };
    applyAt(time);
    return { time, slots: snapshot() };
  });
  result.animations[name] = { duration: animation.duration, frames };
}
result.events = {};
for (const [name, steps] of Object.entries(request.events || {})) {
  const animation = data.findAnimation(name);
  if (!animation) {
    console.error(`no animation '${name}' in ${skeletonPath}`);
    process.exit(2);
  }
  result.events[name] = steps.map(([lastTime, time, loop]) => {
    setupPose();
    const fired = [];
    if (v43) animation.apply(skeleton, lastTime, time, loop, fired, 1, spine.MixFrom.setup, false, false, false);
    else animation.apply(skeleton, lastTime, time, loop, fired, 1, spine.MixBlend.setup, spine.MixDirection.mixIn);
    return fired.map((e) => ({
      name: e.data.name, time: e.time, int: e.intValue, float: e.floatValue, string: e.stringValue,
      audio: e.data.audioPath ? { path: e.data.audioPath, volume: e.volume, balance: e.balance } : null,
    }));
  });
}
fs.writeFileSync(outPath, JSON.stringify(result));

// What SkeletonJson.js (4.2, or 4.3 where it differs) reads; anything else it ignores without a
// word.
function lint(json, atlas) {
  const out = [];
  const line = v43 ? "4.3" : "4.2";
  const only = (where, obj, keys) => {
    for (const k of Object.keys(obj || {})) if (!keys.includes(k)) out.push(`${where}: key '${k}' is not read by the ${line} runtime`);
  };
  const constraintBlocks = v43 ? ["constraints"] : ["ik", "transform", "path", "physics"];
  only("top level", json, ["skeleton", "bones", "slots", ...constraintBlocks, "skins", "events", "animations"]);
  only("skeleton", json.skeleton, ["hash", "spine", "x", "y", "width", "height", "referenceScale", "fps", "images", "audio"]);
  const boneIndex = new Map();
  (json.bones || []).forEach((b, i) => {
    only(`bone ${b.name}`, b, ["name", "parent", "length", "x", "y", "rotation", "scaleX", "scaleY", "shearX", "shearY", "inherit", "skin", "color"]);
    if (b.parent !== undefined && !boneIndex.has(b.parent)) out.push(`bone ${b.name}: parent '${b.parent}' is not listed before it`);
    if (boneIndex.has(b.name)) out.push(`bone ${b.name}: listed twice`);
    boneIndex.set(b.name, i);
  });
  const constraints = new Set();
  const iks = v43 ? (json.constraints || []).filter((k) => k.type === "ik") : json.ik || [];
  if (v43 && iks.length !== (json.constraints || []).length) out.push("constraints: a type other than 'ik' (sinew writes IK only)");
  iks.forEach((k, i) => {
    const fields = v43 ? ["type", "name", "skin", "bones", "target", "mix", "softness", "bendPositive", "compress", "stretch", "scaleY"]
      : ["name", "order", "skin", "bones", "target", "mix", "softness", "bendPositive", "compress", "stretch", "uniform"];
    only(`ik ${k.name}`, k, fields);
    if (constraints.has(k.name)) out.push(`ik ${k.name}: listed twice`);
    constraints.add(k.name);
    if (!(k.bones.length === 1 || k.bones.length === 2)) out.push(`ik ${k.name}: ${k.bones.length} bones (the runtime solves 1 or 2)`);
    if (!v43 && k.order !== i) out.push(`ik ${k.name}: order ${k.order} at position ${i}`);
    for (const b of [...k.bones, k.target]) if (!boneIndex.has(b)) out.push(`ik ${k.name}: unknown bone ${b}`);
  });
  (v43 ? [] : json.physics || []).forEach((p, i) => {
    only(`physics ${p.name}`, p, ["name", "order", "skin", "bone", "x", "y", "rotate", "scaleX", "shearX", "limit", "fps", "inertia",
      "strength", "damping", "mass", "wind", "gravity", "mix", "inertiaGlobal", "strengthGlobal", "dampingGlobal", "massGlobal",
      "windGlobal", "gravityGlobal", "mixGlobal"]);
    if (constraints.has(p.name)) out.push(`physics ${p.name}: name taken`);
    constraints.add(p.name);
    if (!boneIndex.has(p.bone)) out.push(`physics ${p.name}: unknown bone ${p.bone}`);
    if (p.order !== iks.length + i) out.push(`physics ${p.name}: order ${p.order}, expected ${iks.length + i}`);
  });
  const events = new Set(Object.keys(json.events || {}));
  for (const [name, e] of Object.entries(json.events || {})) {
    only(`event ${name}`, e, ["int", "float", "string", "audio", "volume", "balance"]);
    if ((e.volume !== undefined || e.balance !== undefined) && !e.audio) out.push(`event ${name}: volume or balance without audio (not read)`);
  }
  const slots = new Map();
  for (const s of json.slots || []) {
    only(`slot ${s.name}`, s, ["name", "bone", "color", "dark", "attachment", "blend", "visible"]);
    slots.set(s.name, s);
  }
  if (!Array.isArray(json.skins)) out.push("skins: not an array (3.7 layout): no skins load");
  const attachmentsOf = new Map();
  for (const skin of json.skins || []) {
    only(`skin ${skin.name}`, skin, ["name", "bones", "ik", "transform", "path", "physics", "attachments"]);
    for (const [slotName, entries] of Object.entries(skin.attachments || {})) {
      for (const [key, a] of Object.entries(entries)) {
        const where = `skin ${skin.name}, ${slotName}/${key}`;
        attachmentsOf.set(`${slotName}/${key}`, a);
        const type = a.type || "region";
        if (type === "linkedmesh") {
          // A skin's choice: the default skin's mesh of that name in this slot, no geometry of its own.
          const sourceKey = v43 ? "source" : "parent";
          only(where, a, ["type", "name", "path", sourceKey, "skin", "timelines", "color", "width", "height"]);
          const owner = (json.skins || []).find((s) => s.name === (a.skin || "default"));
          const source = owner && (owner.attachments[slotName] || {})[a[sourceKey]];
          if (!source || source.type !== "mesh") out.push(`${where}: linked mesh's ${sourceKey} '${a[sourceKey]}' is no mesh of skin '${a.skin || "default"}' in this slot`);
          const region = a.path || a.name || key;
          if (!atlas.findRegion(region)) out.push(`${where}: region '${region}' is not in the atlas`);
          continue;
        }
        if (type !== "mesh") { out.push(`${where}: type '${type}' (sinew writes meshes and linked meshes only)`); continue; }
        only(where, a, ["type", "name", "path", "uvs", "triangles", "vertices", "hull", "edges", "width", "height", "color", "sequence"]);
        const region = a.path || a.name || key;
        if (!atlas.findRegion(region)) out.push(`${where}: region '${region}' is not in the atlas`);
        const n = a.uvs.length / 2;
        if (a.vertices.length === a.uvs.length) { out.push(`${where}: unweighted`); continue; }
        let i = 0, count = 0;
        while (i < a.vertices.length) {
          const bones = a.vertices[i++];
          let sum = 0;
          for (let k = 0; k < bones; k++, i += 4) {
            if (!(a.vertices[i] >= 0 && a.vertices[i] < json.bones.length)) out.push(`${where}: vertex ${count} names bone ${a.vertices[i]}`);
            sum += a.vertices[i + 3];
          }
          if (Math.abs(sum - 1) > 1e-6) out.push(`${where}: vertex ${count} weights sum to ${sum}`);
          count++;
        }
        if (count !== n) out.push(`${where}: ${count} weighted vertices but ${n} uvs`);
        if (a.triangles.some((v) => v >= n)) out.push(`${where}: triangle index out of range`);
        if (a.hull > n) out.push(`${where}: hull ${a.hull} > ${n} vertices`);
      }
    }
  }
  for (const s of json.slots || []) {
    if (s.attachment && !attachmentsOf.has(`${s.name}/${s.attachment}`)) out.push(`slot ${s.name}: setup attachment '${s.attachment}' is not in a skin`);
  }
  const curveOk = (where, key, next, channels) => {
    if (key.curve === undefined || key.curve === "stepped") return;
    if (!Array.isArray(key.curve) || key.curve.length !== 4 * channels) { out.push(`${where}: curve of ${key.curve.length} numbers, expected ${4 * channels}`); return; }
    for (let c = 0; c < channels; c++) {
      const [cx1, , cx2] = key.curve.slice(4 * c, 4 * c + 4);
      if (next && !(cx1 >= (key.time || 0) && cx2 <= next.time && cx1 <= cx2 + 1e-9)) out.push(`${where}: curve handles outside the segment`);
    }
  };
  const keysOk = (where, keys, fields, channels) => {
    let last = -Infinity;
    keys.forEach((k, i) => {
      only(`${where} key ${i}`, k, ["time", "curve", ...fields]);
      const t = k.time || 0;
      if (!(t >= last)) out.push(`${where} key ${i}: time goes back`);
      last = t;
      curveOk(`${where} key ${i}`, k, keys[i + 1], channels);
    });
  };
  for (const [name, a] of Object.entries(json.animations || {})) {
    only(`animation ${name}`, a, ["slots", "bones", "ik", "transform", "path", "physics", "attachments", "drawOrder", "events"]);
    for (const [bone, timelines] of Object.entries(a.bones || {})) {
      if (!boneIndex.has(bone)) out.push(`animation ${name}: unknown bone ${bone}`);
      for (const [kind, keys] of Object.entries(timelines)) {
        const where = `animation ${name}, bone ${bone}, ${kind}`;
        if (kind === "rotate") keysOk(where, keys, ["value"], 1);
        else if (["translate", "scale", "shear"].includes(kind)) keysOk(where, keys, ["x", "y"], 2);
        else out.push(`${where}: timeline sinew does not write`);
      }
    }
    for (const [slot, timelines] of Object.entries(a.slots || {})) {
      if (!slots.has(slot)) out.push(`animation ${name}: unknown slot ${slot}`);
      for (const [kind, keys] of Object.entries(timelines)) {
        const where = `animation ${name}, slot ${slot}, ${kind}`;
        if (kind === "rgba") keysOk(where, keys, ["color"], 4);
        else if (kind === "attachment") keysOk(where, keys, ["name"], 0);
        else out.push(`${where}: timeline sinew does not write`);
      }
    }
    for (const [constraint, keys] of Object.entries(a.ik || {})) {
      if (!constraints.has(constraint)) out.push(`animation ${name}: unknown IK constraint ${constraint}`);
      keysOk(`animation ${name}, ik ${constraint}`, keys, ["mix", "softness", "bendPositive", "compress", "stretch"], 2);
    }
    for (const [skin, slotsMap] of Object.entries(a.attachments || {})) {
      for (const [slot, entries] of Object.entries(slotsMap)) {
        for (const [key, timelines] of Object.entries(entries)) {
          const where = `animation ${name}, attachments ${skin}/${slot}/${key}`;
          const att = attachmentsOf.get(`${slot}/${key}`);
          if (!att) { out.push(`${where}: no such attachment`); continue; }
          let influences = 0;
          for (let i = 0; i < att.vertices.length; i += 1 + 4 * att.vertices[i]) influences += att.vertices[i];
          for (const [kind, keys] of Object.entries(timelines)) {
            if (kind !== "deform") { out.push(`${where}, ${kind}: timeline sinew does not write`); continue; }
            keysOk(`${where}, deform`, keys, ["vertices", "offset"], 1);
            keys.forEach((k, i) => {
              if ((k.offset || 0) + (k.vertices || []).length > 2 * influences) out.push(`${where}, deform key ${i}: ${k.vertices.length} numbers for ${influences} influences`);
            });
          }
        }
      }
    }
    let lastEvent = -Infinity;
    for (const [i, k] of (a.events || []).entries()) {
      only(`animation ${name}, events key ${i}`, k, ["time", "name", "int", "float", "string", "volume", "balance"]);
      if (!events.has(k.name)) out.push(`animation ${name}, events key ${i}: unknown event ${k.name}`);
      if (!((k.time || 0) >= lastEvent)) out.push(`animation ${name}, events key ${i}: time goes back`);
      lastEvent = k.time || 0;
    }
    for (const [i, k] of (a.drawOrder || []).entries()) {
      only(`animation ${name}, drawOrder key ${i}`, k, ["time", "offsets"]);
      let previous = -1;
      for (const o of k.offsets || []) {
        const index = (json.slots || []).findIndex((s) => s.name === o.slot);
        if (index <= previous) out.push(`animation ${name}, drawOrder key ${i}: offsets not in setup order`);
        previous = index;
      }
    }
  }
  return out;
}
