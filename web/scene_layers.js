// Turns one /api/scene document into three.js objects, one THREE.Group per layer.
// Everything is built in world coordinates (the first camera's frame: x right, y down,
// z forward); the caller flips the root for display. Each layer is a handful of buffer
// geometries whatever the map size (all keyframe frustums share one LineSegments), so
// 100k points and 1000 keyframes stay a few draw calls.
import * as THREE from 'three';
import { heightColours, ageColours, quantile, sortedSample } from './point_colours.js';

export const LAYER_NAMES = ['points', 'lines', 'keyframes', 'camera', 'trajectory',
                            'ground-truth', 'loops', 'covisibility', 'local-map'];

const material = {
  points: new THREE.PointsMaterial({ size: 2, sizeAttenuation: false, vertexColors: true }),
  lines: new THREE.LineBasicMaterial({ color: 0xd0d4dc }),
  keyframes: new THREE.LineBasicMaterial({ color: 0x3d6bff }),
  // The current camera is never hidden: it is where the user looks for "where am I".
  camera: new THREE.LineBasicMaterial({ color: 0xff2a2a, depthTest: false }),
  trajectory: new THREE.LineBasicMaterial({ color: 0xc77dff }),
  groundTruth: new THREE.LineBasicMaterial({ color: 0x63e67f }),
  // A loop joins two keyframes that are often a few centimetres apart, inside the blue frustums:
  // drawn over them, with a dot at each end, so that every closed loop can be found.
  loops: new THREE.LineBasicMaterial({ color: 0xff7a1a, depthTest: false }),
  loopEnds: new THREE.PointsMaterial({ size: 7, sizeAttenuation: false, color: 0xff7a1a, depthTest: false }),
  covisibility: new THREE.LineBasicMaterial({ color: 0x9fb0a0, transparent: true, opacity: 0.35,
                                              depthWrite: false }),
  localKeyframes: new THREE.LineBasicMaterial({ color: 0x8fe3ff }),
  // The local map is a highlight: drawn last and without depth test so it is never hidden.
  localPoints: new THREE.PointsMaterial({ size: 3, sizeAttenuation: false, color: 0xff5a1f,
                                          depthTest: false }),
};

const FRUSTUM_VERTICES = 16;            // 8 segments: 4 edges from the centre, 4 around the image
const DEFAULT_CORNERS = [[-0.6, -0.45], [0.6, -0.45], [0.6, 0.45], [-0.6, 0.45]];  // 4:3

// Image corners on the z = 1 plane of the camera, clockwise from top-left.
function frustumCorners(model) {
  if (!model || !(model.fx > 0) || !(model.fy > 0) || !(model.width > 0) || !(model.height > 0)) {
    return DEFAULT_CORNERS;
  }
  const x0 = -model.cx / model.fx, x1 = (model.width - model.cx) / model.fx;
  const y0 = -model.cy / model.fy, y1 = (model.height - model.cy) / model.fy;
  return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
}

// Writes one frustum (T_world_camera as 12 row-major numbers at poses[at..]) as line segments.
function writeFrustum(out, offset, poses, at, corners, depth) {
  const p = (i) => poses[at + i];
  const world = corners.map(([x, y]) => [
    (p(0) * x + p(1) * y + p(2)) * depth + p(3),
    (p(4) * x + p(5) * y + p(6)) * depth + p(7),
    (p(8) * x + p(9) * y + p(10)) * depth + p(11),
  ]);
  const apex = [p(3), p(7), p(11)];
  let o = offset * 3;
  const put = (v) => { out[o++] = v[0]; out[o++] = v[1]; out[o++] = v[2]; };
  for (let k = 0; k < 4; k++) { put(apex); put(world[k]); }
  for (let k = 0; k < 4; k++) { put(world[k]); put(world[(k + 1) % 4]); }
}

function frustums(poses, indices, corners, depth) {
  const out = new Float32Array(indices.length * FRUSTUM_VERTICES * 3);
  indices.forEach((k, n) => writeFrustum(out, n * FRUSTUM_VERTICES, poses, k * 12, corners, depth));
  return out;
}

function geometry(positions) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  return g;
}

// While the view moves on a slow (software) renderer, points and lines are drawn thinned:
// a second object shares the full geometry's buffers and draws every k-th item through an index.
const COARSE_POINTS = 20000;
const COARSE_SEGMENTS = 3000;

function coarseCopy(full, count, budget, verticesPerItem) {
  const stride = Math.ceil(count / budget);
  const kept = Math.ceil(count / stride);
  const index = new Uint32Array(kept * verticesPerItem);
  for (let n = 0; n < kept; n++) {
    for (let v = 0; v < verticesPerItem; v++) index[n * verticesPerItem + v] = n * stride * verticesPerItem + v;
  }
  const g = new THREE.BufferGeometry();
  for (const [name, attribute] of Object.entries(full.geometry.attributes)) g.setAttribute(name, attribute);
  g.setIndex(new THREE.BufferAttribute(index, 1));
  const copy = new full.constructor(g, full.material);
  copy.visible = false;
  return copy;
}

function centreOf(poses, k) {
  return [poses[k * 12 + 3], poses[k * 12 + 7], poses[k * 12 + 11]];
}

// Segments between keyframe centres for [id_a, id_b, ...] pairs; pairs naming an unknown id are skipped.
function edgeSegments(edges, indexOfId, poses) {
  const out = new Float32Array(edges.length * 6);
  let n = 0;
  for (const edge of edges) {
    const a = indexOfId.get(edge[0]), b = indexOfId.get(edge[1]);
    if (a === undefined || b === undefined) continue;
    out.set(centreOf(poses, a), n * 6);
    out.set(centreOf(poses, b), n * 6 + 3);
    n++;
  }
  return out.subarray(0, n * 6);
}

// A robust box of the scene: 2nd..98th percentile of the points per axis, grown to hold
// every camera centre. Returns its centre (world) and the radius of its bounding sphere.
export function sceneBounds(doc) {
  const box = new THREE.Box3();
  const xyz = doc.points?.xyz ?? [];
  if (xyz.length >= 3) {
    const low = [], high = [];
    for (let a = 0; a < 3; a++) {
      const sorted = sortedSample(xyz, a);
      low.push(quantile(sorted, 0.02)); high.push(quantile(sorted, 0.98));
    }
    box.set(new THREE.Vector3(...low), new THREE.Vector3(...high));
  }
  const grow = (list) => {
    for (let i = 0; i + 2 < list.length; i += 3) box.expandByPoint(new THREE.Vector3(list[i], list[i + 1], list[i + 2]));
  };
  grow(doc.trajectory ?? []);
  const poses = doc.keyframes?.poses ?? [];
  for (let k = 0; k * 12 + 11 < poses.length; k++) grow(centreOf(poses, k));
  if (doc.camera) grow(centreOf(doc.camera, 0));
  if (box.isEmpty()) return { centre: new THREE.Vector3(), radius: 1 };
  const sphere = box.getBoundingSphere(new THREE.Sphere());
  return { centre: sphere.center, radius: Math.max(sphere.radius, 0.05) };
}

// Keyframe frustum depth: 0.7 of the median spacing of consecutive keyframes, so
// neighbours barely overlap, kept within 0.6 %..3 % of the scene radius to stay visible.
function frustumDepth(poses, count, radius) {
  const gaps = [];
  for (let k = 1; k < count; k++) {
    const a = centreOf(poses, k - 1), b = centreOf(poses, k);
    gaps.push(Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]));
  }
  gaps.sort((a, b) => a - b);
  const spacing = gaps.length ? gaps[gaps.length >> 1] : 0;
  return Math.min(Math.max(0.7 * spacing, 0.006 * radius), 0.03 * radius);
}

export class SceneLayers {
  constructor(root) {
    this.groups = {};
    for (const name of LAYER_NAMES) {
      this.groups[name] = new THREE.Group();
      this.groups[name].name = name;
      root.add(this.groups[name]);
    }
    this.groups.covisibility.visible = false;      // a dense web: off unless asked for
    this.pointColour = 'height';
    this.pointsObject = null;
    this.points = { ids: [], xyz: [] };
    this.coarse = false;
    this.coarsePairs = [];          // [full, thinned] objects, swapped by setCoarse
    this.drawn = Object.fromEntries(LAYER_NAMES.map((name) => [name, 0]));
  }

  setVisible(name, on) { this.groups[name].visible = on; }
  isVisible(name) { return this.groups[name].visible; }

  // Replaces every layer's content with the document's; visibility is kept.
  update(doc, bounds) {
    for (const group of Object.values(this.groups)) {
      // Thinned copies share their buffers with the full objects: disposing either frees both.
      for (const child of group.children) child.geometry.dispose();
      group.clear();
    }
    for (const name of LAYER_NAMES) this.drawn[name] = 0;
    this.coarsePairs = [];
    this.pointsObject = null;

    this.buildPointsAndLines(doc);
    const keyframes = this.buildKeyframes(doc, bounds);
    this.buildPaths(doc);
    if (doc.local_map) this.buildLocalMap(doc.local_map, keyframes);
    this.setCoarse(this.coarse);
  }

  add(name, object, drawn) {
    this.groups[name].add(object);
    this.drawn[name] = drawn;
  }

  // Adds `object` and, above `budget` items, its thinned copy for moving views.
  addWithCoarse(name, object, drawn, budget, verticesPerItem) {
    this.add(name, object, drawn);
    if (drawn <= budget) return;
    const coarse = coarseCopy(object, drawn, budget, verticesPerItem);
    this.groups[name].add(coarse);
    this.coarsePairs.push([object, coarse]);
  }

  buildPointsAndLines(doc) {
    const xyz = doc.points?.xyz ?? [];
    const pointCount = Math.floor(xyz.length / 3);
    let ids = doc.points?.ids ?? [];
    if (ids.length !== pointCount) ids = Array.from({ length: pointCount }, (_, i) => i);
    this.points = { ids, xyz };
    if (pointCount > 0) {
      const g = geometry(Float32Array.from(xyz));
      g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(pointCount * 3), 3));
      this.pointsObject = new THREE.Points(g, material.points);
      this.recolourPoints();
      this.addWithCoarse('points', this.pointsObject, pointCount, COARSE_POINTS, 1);
    }
    const lineXyz = doc.lines?.xyz ?? [];
    const segments = Math.floor(lineXyz.length / 6);
    if (segments > 0) {
      const lines = new THREE.LineSegments(geometry(Float32Array.from(lineXyz.slice(0, segments * 6))), material.lines);
      this.addWithCoarse('lines', lines, segments, COARSE_SEGMENTS, 2);
    }
  }

  // Keyframe frustums, the current camera, loop and covisibility edges. Returns what the
  // local map needs to find its keyframes again.
  buildKeyframes(doc, bounds) {
    const ids = doc.keyframes?.ids ?? [];
    const poses = doc.keyframes?.poses ?? [];
    const count = Math.min(ids.length, Math.floor(poses.length / 12));
    const indexOfId = new Map();
    for (let k = 0; k < count; k++) indexOfId.set(ids[k], k);
    const corners = frustumCorners(doc.camera_model);
    const depth = frustumDepth(poses, count, bounds.radius);
    if (count > 0) {
      const all = Array.from({ length: count }, (_, k) => k);
      this.add('keyframes', new THREE.LineSegments(geometry(frustums(poses, all, corners, depth)), material.keyframes), count);
    }
    if (doc.camera && doc.camera.length === 12) {
      const size = Math.max(3 * depth, 0.025 * bounds.radius);     // findable at a glance
      const current = new THREE.LineSegments(geometry(frustums(doc.camera, [0], corners, size)), material.camera);
      current.renderOrder = 3;                   // after the local map's points
      this.add('camera', current, 1);
    }
    const loops = edgeSegments(doc.loop_edges ?? [], indexOfId, poses);
    if (loops.length > 0) {
      const edges = new THREE.LineSegments(geometry(loops), material.loops);
      const ends = new THREE.Points(geometry(loops), material.loopEnds);
      edges.renderOrder = ends.renderOrder = 3;
      this.add('loops', edges, loops.length / 6);
      this.groups.loops.add(ends);
    }
    const covisible = edgeSegments(doc.covisibility ?? [], indexOfId, poses);
    if (covisible.length > 0) {
      this.add('covisibility', new THREE.LineSegments(geometry(covisible), material.covisibility), covisible.length / 6);
    }
    return { indexOfId, poses, corners, depth };
  }

  // Estimated trajectory and ground truth, as polylines.
  buildPaths(doc) {
    const paths = [['trajectory', doc.trajectory, material.trajectory],
                   ['ground-truth', doc.ground_truth?.positions, material.groundTruth]];
    for (const [name, list, lineMaterial] of paths) {
      const n = Math.floor((list ?? []).length / 3);
      if (n >= 2) this.add(name, new THREE.Line(geometry(Float32Array.from(list.slice(0, n * 3))), lineMaterial), n);
    }
  }

  // Thinned points and lines (true) or everything (false).
  setCoarse(on) {
    this.coarse = on;
    for (const [full, coarse] of this.coarsePairs) { full.visible = !on; coarse.visible = on; }
  }

  // The local map drawn again over the rest: its keyframes brighter, its points in orange.
  buildLocalMap(localMap, { indexOfId, poses, corners, depth }) {
    const group = this.groups['local-map'];
    const local = (localMap.keyframes ?? []).map((id) => indexOfId.get(id)).filter((k) => k !== undefined);
    if (local.length > 0) {
      const frames = new THREE.LineSegments(geometry(frustums(poses, local, corners, depth)), material.localKeyframes);
      frames.renderOrder = 1;                    // after the blue ones, so it wins on equal depth
      group.add(frames);
    }
    const indexOfPoint = new Map();
    this.points.ids.forEach((id, i) => indexOfPoint.set(id, i));
    const xyz = this.points.xyz;
    const chosen = (localMap.points ?? []).map((id) => indexOfPoint.get(id)).filter((i) => i !== undefined);
    if (chosen.length > 0) {
      const out = new Float32Array(chosen.length * 3);
      chosen.forEach((i, n) => { out[n * 3] = xyz[i * 3]; out[n * 3 + 1] = xyz[i * 3 + 1]; out[n * 3 + 2] = xyz[i * 3 + 2]; });
      const points = new THREE.Points(geometry(out), material.localPoints);
      points.renderOrder = 2;
      group.add(points);
    }
    this.drawn['local-map'] = local.length + chosen.length;
  }

  setPointColour(mode) {
    this.pointColour = mode === 'age' ? 'age' : 'height';
    this.recolourPoints();
  }

  recolourPoints() {
    if (!this.pointsObject) return;
    const colour = this.pointsObject.geometry.getAttribute('color');
    if (this.pointColour === 'age') ageColours(this.points.ids, colour.array);
    else heightColours(this.points.xyz, colour.array);
    colour.needsUpdate = true;
  }
}
