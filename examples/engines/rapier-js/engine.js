#!/usr/bin/env node
// Rapier (npm `@dimforge/rapier3d-compat` 0.21.0, WebAssembly, single
// precision) as a sweeptrace engine (docs/ENGINE_PROTOCOL.md): each sweep is
// answered by Rapier's own `World.castShape` of a `Ball` (the ball's radius)
// from p0 along d = p1 - p0, with target distance 0 and max time of impact 1,
// against a fixed rigid body whose collider is the scene's mesh as a default
// trimesh (no `TriMeshFlags`).
//
//   npm ci --prefix examples/engines/rapier-js
//   sweeptrace check traces/ --engine "node examples/engines/rapier-js/engine.js"
//
// `stopAtPenetration` is true (Rapier's default): a ball that starts
// overlapping the mesh is a hit at time 0 whatever its direction.
// `--no-stop-at-penetration` (or RAPIER_STOP_AT_PENETRATION=false in the
// environment) casts with false: such a ball is a hit only when its path
// goes deeper.
//
// Rapier does not say which triangle a shape cast hit. The answer's triangle
// is the one whose own cast reproduces the hit: Rapier's ball-vs-triangle
// cast (`Triangle.castShape`, the pairwise query the trimesh runs on each of
// its triangles) is run on the triangles nearest the hit's witness point,
// and the first whose time of impact, witness point and normal equal the
// mesh cast's bit for bit is named.
import RAPIER from '@dimforge/rapier3d-compat';
import { createInterface } from 'node:readline';

function fail(message) {
  process.stderr.write(`rapier engine: ${message}\n`);
  process.exit(2);
}

// --stop-at-penetration / --no-stop-at-penetration, else the environment,
// else Rapier's default (true).
function stopAtPenetrationSetting() {
  const args = process.argv.slice(2);
  for (const arg of args) {
    if (!['--stop-at-penetration', '--no-stop-at-penetration'].includes(arg)) {
      fail(`unknown argument \`${arg}\` (--stop-at-penetration, --no-stop-at-penetration)`);
    }
  }
  if (args.length > 0) return args[args.length - 1] === '--stop-at-penetration';
  const value = process.env.RAPIER_STOP_AT_PENETRATION;
  if (value === undefined || value === '') return true;
  if (['true', '1'].includes(value)) return true;
  if (['false', '0'].includes(value)) return false;
  return fail(`RAPIER_STOP_AT_PENETRATION=${value}: expected true or false (1 or 0)`);
}
const stopAtPenetration = stopAtPenetrationSetting();

// A barycentric weight at most this counts as 0 when the contact point is
// classified (face / edge / vertex): a fraction of the triangle's altitude,
// as in the Jolt example.
const BARY_EPS = 1e-4;
// The triangles tried first for the triangle of a hit: those within this
// distance of the witness point, relative to the sweep's scale (the witness
// lies on its triangle up to single-precision rounding).
const NEAR = 1e-5;

await RAPIER.init();
const ORIGIN = { x: 0, y: 0, z: 0 };
const IDENTITY = { w: 1, x: 0, y: 0, z: 0 };

// The current scene: its key (vertices and triangles), corners, Rapier world,
// and the Rapier triangles of the reproduction (made when first needed).
let scene = null;
const balls = new Map(); // radius -> Ball

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const xyz = (v) => [v.x, v.y, v.z];
const vec = ([x, y, z]) => ({ x, y, z });

// A scene replaces the previous one unless its mesh is the same (a suite
// sends the same scene again for each trace or case): then nothing is rebuilt.
function loadScene(msg) {
  const key = JSON.stringify([msg.vertices, msg.triangles]);
  if (scene && scene.key === key) return;
  if (scene && scene.world) scene.world.free();
  const corners = msg.triangles.map((t) => t.map((i) => msg.vertices[i]));
  scene = { key, corners, world: null, shapes: new Map() };
  if (msg.triangles.length === 0) return; // nothing to hit: every sweep misses
  const vertices = new Float32Array(msg.vertices.flat());
  const indices = new Uint32Array(msg.triangles.flat());
  try {
    const world = new RAPIER.World({ x: 0, y: 0, z: 0 });
    const body = world.createRigidBody(RAPIER.RigidBodyDesc.fixed());
    world.createCollider(RAPIER.ColliderDesc.trimesh(vertices, indices), body);
    world.step(); // puts the collider in the broad phase the queries walk
    scene.world = world;
  } catch (e) {
    fail(`scene \`${msg.name ?? ''}\`: the trimesh collider: ${e.message ?? e}`);
  }
}

function ball(radius) {
  let shape = balls.get(radius);
  if (!shape) {
    shape = new RAPIER.Ball(radius);
    balls.set(radius, shape);
  }
  return shape;
}

// Rapier's triangle `t` of the scene (its corners rounded to f32 as the
// trimesh's are).
function triangleShape(t) {
  let shape = scene.shapes.get(t);
  if (!shape) {
    shape = new RAPIER.Triangle(...scene.corners[t].map(vec));
    scene.shapes.set(t, shape);
  }
  return shape;
}

// The squared distance from p to triangle (a, b, c) (Ericson's closest point).
function distanceSquared(p, [a, b, c]) {
  const ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const d1 = dot(ab, ap), d2 = dot(ac, ap);
  let q;
  if (d1 <= 0 && d2 <= 0) q = a;
  else {
    const bp = sub(p, b), d3 = dot(ab, bp), d4 = dot(ac, bp);
    const cp = sub(p, c), d5 = dot(ab, cp), d6 = dot(ac, cp);
    const vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
    if (d3 >= 0 && d4 <= d3) q = b;
    else if (d6 >= 0 && d5 <= d6) q = c;
    else if (vc <= 0 && d1 >= 0 && d3 <= 0) q = add(a, scale(ab, d1 / (d1 - d3)));
    else if (vb <= 0 && d2 >= 0 && d6 <= 0) q = add(a, scale(ac, d2 / (d2 - d6)));
    else if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) q = add(b, scale(sub(c, b), (d4 - d3) / (d4 - d3 + d5 - d6)));
    else {
      const denom = va + vb + vc;
      if (!(denom > 0)) return Math.min(...[a, b, c].map((v) => dot(sub(p, v), sub(p, v)))); // degenerate
      q = add(a, add(scale(ab, vb / denom), scale(ac, vc / denom)));
    }
  }
  const pq = sub(p, q);
  return dot(pq, pq);
}

const sameBits = (hit, other) => other !== null
  && other.time_of_impact === hit.time_of_impact
  && ['witness1', 'normal1'].every((k) => ['x', 'y', 'z'].every((c) => other[k][c] === hit[k][c]));

// The triangle of a mesh cast's hit: of the triangles in order of their
// distance from the witness point (the near ones first, then, if none of
// them does, all), the first whose own cast reproduces the hit bit for bit.
// Among equally near ones the lower index is tried first. -1 if none does.
function triangleOf(hit, shape, p0, d, sweepScale) {
  const witness = xyz(hit.witness1);
  const order = scene.corners
    .map((c, t) => [distanceSquared(witness, c), t])
    .map(([d2, t]) => [Number.isNaN(d2) ? Infinity : d2, t]) // a degenerate triangle: last
    .sort((x, y) => x[0] - y[0] || x[1] - y[1]);
  const near = (NEAR * sweepScale) ** 2;
  const tried = (t) => sameBits(hit, triangleShape(t).castShape(
    ORIGIN, IDENTITY, ORIGIN, shape, vec(p0), IDENTITY, vec(d), 0, 1, stopAtPenetration));
  const first = order.find(([d2, t]) => d2 <= near && tried(t)) ?? order.find(([d2, t]) => !(d2 <= near) && tried(t));
  return first ? first[1] : -1;
}

// Kind and feature of a contact point p on triangle (a, b, c), from its
// barycentric weights w[i] (of vertex i): two weights ~0 -> vertex i (the one
// near 1), one weight w[k] ~0 -> edge (k+1)%3 (joining k+1 and k+2), else face.
function classify(p, [a, b, c]) {
  const n = cross(sub(b, a), sub(c, a)), nn = dot(n, n);
  const w = [dot(n, cross(sub(b, p), sub(c, p))) / nn, dot(n, cross(sub(c, p), sub(a, p))) / nn, 0];
  w[2] = 1 - w[0] - w[1];
  const zero = w.map((x) => x <= BARY_EPS);
  const count = zero.filter(Boolean).length;
  if (count >= 2) return { kind: 'vertex', feature: w.indexOf(Math.max(...w)) };
  if (count === 1) return { kind: 'edge', feature: (zero.indexOf(true) + 1) % 3 };
  return { kind: 'face', feature: null };
}

function sweep(msg) {
  const none = { frame: msg.frame, ball: msg.ball, alpha: 1, kind: 'none' };
  if (!scene) fail(`the sweep of frame ${msg.frame}, ball ${msg.ball} arrived before any scene`);
  if (!scene.world) return none;
  const [p0, p1] = [msg.p0, msg.p1], d = sub(p1, p0), shape = ball(msg.radius);
  const hit = scene.world.castShape(vec(p0), IDENTITY, vec(d), shape, 0, 1, stopAtPenetration);
  if (!hit) return none;
  const sweepScale = Math.max(...p0.map(Math.abs), ...p1.map(Math.abs)) + msg.radius;
  const triangle = triangleOf(hit, shape, p0, d, sweepScale);
  if (triangle < 0) {
    fail(`frame ${msg.frame}, ball ${msg.ball}: no triangle's own cast reproduces the hit `
      + `(time of impact ${hit.time_of_impact}, witness ${xyz(hit.witness1)})`);
  }
  const contact = xyz(hit.witness1); // on the mesh, world space
  // normal1 is the mesh's outward normal at the contact: toward the ball.
  const n = xyz(hit.normal1), len = Math.sqrt(dot(n, n));
  const normal = n.map((x) => x / len);
  const alpha = Math.min(Math.max(hit.time_of_impact, 0), 1);
  const { kind, feature } = classify(contact, scene.corners[triangle]);
  return { frame: msg.frame, ball: msg.ball, alpha, kind, triangle, feature, normal, contact };
}

// A contact query (`check --engine-contacts`): each triangle's own contact
// with the ball, `Triangle.contactShape` (parry's ball-versus-triangle
// contact, the pairwise query a trimesh's contact manifolds are made of),
// with the query's contact distance as the prediction. No internal-edge fix
// (a default trimesh has no `TriMeshFlags`): at a seam each triangle gives
// its own contact, with its own normal, as a default trimesh collider's
// manifolds do. The triangles far beyond reach are skipped first (in f64,
// with a margin for Rapier's f32). Kind and feature from the contact point,
// as for a sweep.
function contacts(msg) {
  const answer = { type: 'contacts', frame: msg.frame, ball: msg.ball, contacts: [] };
  if (!scene) fail(`the contact query of frame ${msg.frame}, ball ${msg.ball} arrived before any scene`);
  if (!scene.world) return answer;
  // `distance` is left out of a query when it is 0 (docs/ENGINE_PROTOCOL.md).
  const centre = msg.centre, shape = ball(msg.radius), distance = msg.distance ?? 0;
  const reach = msg.radius + distance;
  const size = Math.max(...centre.map(Math.abs), reach);
  const far = (reach * (1 + 1e-3) + 1e-5 * size) ** 2;
  scene.corners.forEach((corners, t) => {
    if (!(distanceSquared(centre, corners) <= far)) return;
    const hit = triangleShape(t).contactShape(ORIGIN, IDENTITY, shape, vec(centre), IDENTITY, distance);
    if (!hit) return;
    const point = xyz(hit.point1); // on the triangle, world space
    const n = xyz(hit.normal1), len = Math.sqrt(dot(n, n)); // outward: toward the ball
    const { kind, feature } = classify(point, corners);
    const contact = { triangle: t, kind, point, separation: hit.distance };
    if (feature !== null) contact.feature = feature;
    if (len > 0) contact.normal = n.map((x) => x / len);
    answer.contacts.push(contact);
  });
  return answer;
}

const lines = createInterface({ input: process.stdin, crlfDelay: Infinity });
let lineNumber = 0;
for await (const line of lines) {
  lineNumber += 1;
  if (line.trim() === '') continue;
  let msg;
  try {
    msg = JSON.parse(line);
  } catch (e) {
    fail(`input line ${lineNumber}: not JSON: ${e.message}`);
  }
  if (msg.type === 'scene') loadScene(msg);
  else if (msg.type === 'sweep') process.stdout.write(JSON.stringify(sweep(msg)) + '\n');
  else if (msg.type === 'contact') process.stdout.write(JSON.stringify(contacts(msg)) + '\n');
  // other types: ignored (protocol v1)
}
