// Checks a sinew glTF export with the real consumers: the Khronos glTF validator (npm
// `gltf-validator`) and three.js (npm `three`: GLTFLoader, AnimationMixer, and the CPU skinning
// of SkinnedMesh.getVertexPosition, morph targets included), both pinned in package.json.
//
//   node check.mjs FILE.glb REQUEST.json OUT.json
//
// REQUEST.json: {"times": {"<animation>": [t, ...]}}. OUT.json: {"validator": {"errors",
// "warnings", "infos", "hints", "messages": [{code, severity, message, pointer}]},
// "meshes": ["<name>", ...], "setup": Snapshot, "animations": {"<name>": {"duration": d,
// "frames": [{"time": t, "meshes": Snapshot}]}}}; Snapshot = {"<mesh>": [x0, y0, z0, ...]} in
// glTF units, each vertex skinned by three.js at that time (the clip played once, clamped at
// its end).
// Exit status: 0 when loaded (validator findings are reported, not fatal), 2 when three.js
// refuses the file.
import fs from "node:fs";
import validator from "gltf-validator";
import * as THREE from "three";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";

const [glbPath, requestPath, outPath] = process.argv.slice(2);
if (!outPath) {
  console.error("usage: node check.mjs FILE.glb REQUEST.json OUT.json");
  process.exit(2);
}
const bytes = fs.readFileSync(glbPath);
const request = JSON.parse(fs.readFileSync(requestPath, "utf8"));

const report = await validator.validateBytes(new Uint8Array(bytes), {
  maxIssues: 1000,
  writeTimestamp: false,
});
const issues = report.issues;

// No DOM here: images are decoded by no one. `self` and a stand-in for createImageBitmap let the loader
// build its textures (their pixels play no part in where vertices go).
globalThis.self = globalThis;
globalThis.createImageBitmap = async () => ({ width: 1, height: 1, close() {} });

const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
let gltf;
try {
  gltf = await new Promise((resolve, reject) =>
    new GLTFLoader().parse(buffer, "", resolve, reject),
  );
} catch (e) {
  console.error(`three.js refused ${glbPath}: ${e.message || e}`);
  process.exit(2);
}

const root = gltf.scene;
// Meshes by their glTF mesh name (three.js renames objects whose names clash with joints').
const meshes = [];
root.traverse((o) => {
  if (o.isSkinnedMesh) {
    const index = gltf.parser.associations.get(o).meshes;
    meshes.push([gltf.parser.json.meshes[index].name, o]);
  }
});

function snapshot() {
  root.updateMatrixWorld(true);
  const out = {};
  const v = new THREE.Vector3();
  for (const [name, mesh] of meshes) {
    const count = mesh.geometry.attributes.position.count;
    const xyz = new Array(3 * count);
    for (let i = 0; i < count; i++) {
      mesh.getVertexPosition(i, v);
      xyz[3 * i] = v.x;
      xyz[3 * i + 1] = v.y;
      xyz[3 * i + 2] = v.z;
    }
    out[name] = xyz;
  }
  return out;
}

const result = {
  validator: {
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages,
  },
  meshes: meshes.map(([name]) => name),
  setup: snapshot(),
  animations: {},
};

for (const [name, times] of Object.entries(request.times || {})) {
  const clip = gltf.animations.find((a) => a.name === name);
  if (!clip) {
    console.error(`no animation '${name}' in ${glbPath}`);
    process.exit(2);
  }
  const frames = [];
  for (const time of times) {
    // A fresh mixer per time: the pose is a function of the clip and the time alone.
    const mixer = new THREE.AnimationMixer(root);
    const action = mixer.clipAction(clip);
    action.setLoop(THREE.LoopOnce, 1);
    action.clampWhenFinished = true;
    action.play();
    mixer.setTime(time);
    frames.push({ time, meshes: snapshot() });
    mixer.stopAllAction();
    mixer.uncacheRoot(root);
  }
  result.animations[name] = { duration: clip.duration, frames };
}
fs.writeFileSync(outPath, JSON.stringify(result));
