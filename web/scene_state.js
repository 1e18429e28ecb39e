// The scene as the page holds it: the last full document with the server's deltas applied
// (src/plslam/viz/live_viewer.h says what a delta holds). Keyframes, points and lines are kept
// by id, so that a delta's upserts and removals cost what they change; document() rebuilds the
// flat arrays the layers draw from.

export class SceneState {
  constructor(full) {
    this.base = { ...full };
    this.keyframes = new Map();
    const kf = full.keyframes ?? { ids: [], poses: [], parents: [] };
    kf.ids.forEach((id, i) => this.keyframes.set(id, { pose: kf.poses.slice(12 * i, 12 * i + 12), parent: kf.parents[i] }));
    this.points = byId(full.points, 3);
    this.lines = byId(full.lines, 6);
    this.trajectory = Array.from(full.trajectory ?? []);
  }

  apply(delta) {
    const b = this.base;
    for (const key of ['revision', 'final', 'counts', 'camera', 'local_map', 'loop_edges', 'covisibility']) {
      if (delta[key] !== undefined) b[key] = delta[key];
    }
    for (const id of delta.keyframes_removed ?? []) this.keyframes.delete(id);
    const kf = delta.keyframes ?? { ids: [] };
    kf.ids.forEach((id, i) => this.keyframes.set(id, { pose: kf.poses.slice(12 * i, 12 * i + 12), parent: kf.parents[i] }));
    upsert(this.points, delta.points, delta.points_removed, 3);
    upsert(this.lines, delta.lines, delta.lines_removed, 6);
    // The whole trajectory when a loop correction or a global BA moved what the page had.
    if (delta.trajectory !== undefined) this.trajectory = Array.from(delta.trajectory);
    for (const v of delta.trajectory_append ?? []) this.trajectory.push(v);
  }

  document() {
    const ids = [...this.keyframes.keys()].sort((a, b) => a - b);
    const poses = [], parents = [];
    for (const id of ids) {
      const k = this.keyframes.get(id);
      poses.push(...k.pose);
      parents.push(k.parent);
    }
    return { ...this.base, keyframes: { ids, poses, parents }, points: flat(this.points, 3), lines: flat(this.lines, 6),
             trajectory: this.trajectory };
  }
}

function byId(part, width) {
  const out = new Map();
  if (!part) return out;
  part.ids.forEach((id, i) => out.set(id, part.xyz.slice(width * i, width * i + width)));
  return out;
}

function upsert(map, part, removed, width) {
  for (const id of removed ?? []) map.delete(id);
  if (!part) return;
  part.ids.forEach((id, i) => map.set(id, part.xyz.slice(width * i, width * i + width)));
}

function flat(map, width) {
  const ids = new Array(map.size);
  const xyz = new Float32Array(map.size * width);
  let i = 0;
  for (const [id, values] of map) {
    ids[i] = id;
    xyz.set(values, i * width);
    ++i;
  }
  return { ids, xyz };
}
