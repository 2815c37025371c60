// The world view's first view ("whole world"): from the south (-y) and above, far enough
// that everything that matters is in the picture: the robots, the objects (the ball, the
// boards) and the walls. Plain numbers, no three.js, so it is tested by itself.

export const FIT_MARGIN = 1.15;  // the boxes fill at most 1 / FIT_MARGIN of the picture
const MIN_SPAN_M = 1.0;  // a lone robot is seen with a metre around it
const DIRECTION = [0, -0.75, 0.85];  // from the target towards the camera, before scaling
const GROWTH = 1.1;
const MAX_TRIES = 60;

const sub = (a, b) => a.map((v, i) => v - b[i]);
const dot = (a, b) => a.reduce((s, v, i) => s + v * b[i], 0);
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => { const n = Math.hypot(...a); return a.map((v) => v / n); };

// Where point lands in a camera at position looking at target (+z up), as fractions of the
// half-width and half-height of the picture (|x|, |y| <= 1 inside), or null behind it.
export function project(point, position, target, fovDeg, aspect) {
  const forward = unit(sub(target, position));
  const right = unit(cross(forward, [0, 0, 1]));
  const up = cross(right, forward);
  const v = sub(point, position);
  const depth = dot(v, forward);
  if (depth <= 0) return null;
  const tanV = Math.tan((fovDeg * Math.PI) / 360);
  return { x: dot(v, right) / (depth * tanV * aspect), y: dot(v, up) / (depth * tanV) };
}

function corners([lo, hi]) {
  const out = [];
  for (const x of [lo[0], hi[0]]) for (const y of [lo[1], hi[1]]) for (const z of [lo[2], hi[2]]) out.push([x, y, z]);
  return out;
}

// boxes: [[min x, y, z], [max x, y, z]] in the world (m); fovDeg: the camera's vertical
// field of view; aspect: width / height. {position, target}, or null without boxes.
export function homeView(boxes, fovDeg, aspect) {
  if (!boxes.length) return null;
  const lo = [0, 1, 2].map((i) => Math.min(...boxes.map((b) => b[0][i])));
  const hi = [0, 1, 2].map((i) => Math.max(...boxes.map((b) => b[1][i])));
  const target = [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, 0];
  const span = Math.max(hi[0] - lo[0], hi[1] - lo[1], MIN_SPAN_M);
  let reach = (FIT_MARGIN * span) / 2 / Math.tan((fovDeg * Math.PI) / 360);
  const points = corners([lo, hi]);
  const inside = (position) => points.every((p) => {
    const at = project(p, position, target, fovDeg, aspect);
    return at && Math.abs(at.x) * FIT_MARGIN <= 1 && Math.abs(at.y) * FIT_MARGIN <= 1;
  });
  let position = DIRECTION.map((d, i) => target[i] + d * reach);
  for (let k = 0; k < MAX_TRIES && !inside(position); k++) {  // a long box seen end on
    reach *= GROWTH;
    position = DIRECTION.map((d, i) => target[i] + d * reach);
  }
  return { position, target };
}
