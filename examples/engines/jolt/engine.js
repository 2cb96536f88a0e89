#!/usr/bin/env node
// Jolt Physics (npm `jolt-physics` 1.1.0 = Jolt 5.6.0, WebAssembly, single
// precision) as a sweeptrace engine (docs/ENGINE_PROTOCOL.md): each sweep is
// answered by Jolt's own NarrowPhaseQuery::CastShape of a SphereShape (the
// ball's radius) against a static MeshShape built from the scene's mesh, with
// Jolt's defaults (EBackFaceMode::IgnoreBackFaces, no margin, active edges).
//
//   npm ci --prefix examples/engines/jolt
//   sweeptrace check traces/ --engine "node examples/engines/jolt/engine.js"
//
// A deliberate mistake for sweeptrace to find: JOLT_VARIANT=NAME in the
// environment or `--variant NAME` (see VARIANTS and README.md).
// `--honour-margin` (or JOLT_HONOUR_MARGIN=1), for measurements only: cast a
// sphere of radius r - margin (the rules' rho) instead of Jolt's r.
import initJolt from 'jolt-physics';
import { createInterface } from 'node:readline';

const VARIANTS = [
  'clean', 'late', 'no_vertex', 'next_triangle', 'back_faces', 'centre_contact', 'flipped_edge_normal',
  'tilted_face_normal', 'half_normal', 'contact_off_plane', 'skin',
  'glued', 'first_hit', 'loose_bary', 'wide_active_edges', 'ghost_flat', 'lost_leaf',
];
const flag = process.argv.indexOf('--variant');
const variant = (flag >= 0 ? process.argv[flag + 1] : process.env.JOLT_VARIANT) || 'clean';
if (!VARIANTS.includes(variant)) fail(`unknown variant \`${variant}\` (one of ${VARIANTS.join(', ')})`);
const honourMargin = process.argv.includes('--honour-margin') || process.env.JOLT_HONOUR_MARGIN === '1';

// A barycentric weight at most this counts as 0 when the contact point is
// classified (face / edge / vertex). It is relative to the triangle (a
// fraction of the altitude) and the same 1e-4 as Jolt's ActiveEdges::FixNormal.
const BARY_EPS = 1e-4;
// Variant `loose_bary`: a threshold 100 times looser, 1 % of the altitude.
const LOOSE_BARY_EPS = 1e-2;

function fail(message) {
  process.stderr.write(`jolt engine: ${message}\n`);
  process.exit(2);
}

const Jolt = await initJolt();
const NON_MOVING = 0, MOVING = 1; // object layers: the mesh, the query

// A physics system with one broad phase layer per object layer (Jolt's examples).
const settings = new Jolt.JoltSettings();
const pairs = new Jolt.ObjectLayerPairFilterTable(2);
pairs.EnableCollision(NON_MOVING, MOVING);
pairs.EnableCollision(MOVING, MOVING);
const layers = new Jolt.BroadPhaseLayerInterfaceTable(2, 2);
layers.MapObjectToBroadPhaseLayer(NON_MOVING, new Jolt.BroadPhaseLayer(0));
layers.MapObjectToBroadPhaseLayer(MOVING, new Jolt.BroadPhaseLayer(1));
settings.mObjectLayerPairFilter = pairs;
settings.mBroadPhaseLayerInterface = layers;
settings.mObjectVsBroadPhaseLayerFilter = new Jolt.ObjectVsBroadPhaseLayerFilterTable(layers, 2, pairs, 2);
const system = new Jolt.JoltInterface(settings).GetPhysicsSystem();
const bodies = system.GetBodyInterface();
const query = system.GetNarrowPhaseQuery();

// Query filters for a moving-layer shape cast, and Jolt's default cast settings.
const bpFilter = new Jolt.DefaultBroadPhaseLayerFilter(settings.mObjectVsBroadPhaseLayerFilter, MOVING);
const objFilter = new Jolt.DefaultObjectLayerFilter(pairs, MOVING);
const bodyFilter = new Jolt.BodyFilter(), shapeFilter = new Jolt.ShapeFilter();
const castSettings = new Jolt.ShapeCastSettings();
if (variant === 'back_faces') castSettings.mBackFaceModeTriangles = Jolt.EBackFaceMode_CollideWithBackFaces;
const unitScale = new Jolt.Vec3(1, 1, 1), baseOffset = new Jolt.RVec3(0, 0, 0);
// Contact queries: Jolt's default collide settings (active edges only, back
// faces ignored). `--ghosts` (or JOLT_GHOSTS=1) switches on
// EActiveEdgeMode::CollideWithAll: every edge reports its geometric normal,
// the ghost contacts Jolt's active edges exist to remove.
const ghosts = process.argv.includes('--ghosts') || process.env.JOLT_GHOSTS === '1';
// Vertices at exactly the same position are welded into one before the
// MeshShape is built, as Jolt's own MeshShapeSettings(TriangleList) does
// (Indexify): Jolt finds a triangle's neighbours by vertex index, so an
// edge shared by position only is a boundary to it, an active edge, and
// its contacts there are ghosts. `--no-weld` (or JOLT_NO_WELD=1) keeps the
// trace's indices, to see those ghosts. The scene's triangles keep their
// indices either way.
const weld = !(process.argv.includes('--no-weld') || process.env.JOLT_NO_WELD === '1');
const collideSettings = new Jolt.CollideShapeSettings();
if (ghosts) collideSettings.mActiveEdgeMode = Jolt.EActiveEdgeMode_CollideWithAll;
if (variant === 'back_faces') collideSettings.mBackFaceMode = Jolt.EBackFaceMode_CollideWithBackFaces;

let scene = null; // { vertices, triangles, body, mesh } of the current scene
const spheres = new Map(); // radius -> SphereShape (kept alive with AddRef)

// A new scene replaces the previous one: its body is removed and destroyed.
function loadScene(msg) {
  if (scene && scene.body) {
    bodies.RemoveBody(scene.body);
    bodies.DestroyBody(scene.body);
  }
  scene = { vertices: msg.vertices, triangles: msg.triangles, margin: msg.margin ?? 0, body: null, mesh: null };
  const vertices = new Jolt.VertexList(), triangles = new Jolt.IndexedTriangleList();
  // index in the trace -> index in Jolt's vertex list (welded: the first
  // vertex at that position; `-0` and `0` are one position).
  const index = [], first = new Map();
  for (const [x, y, z] of msg.vertices) {
    const key = `${x + 0},${y + 0},${z + 0}`;
    if (weld && first.has(key)) {
      index.push(first.get(key));
      continue;
    }
    first.set(key, vertices.size());
    index.push(vertices.size());
    const v = new Jolt.Float3(x, y, z);
    vertices.push_back(v);
    Jolt.destroy(v);
  }
  msg.triangles.forEach(([a, b, c], t) => {
    // User data: the scene's triangle index.
    const tri = new Jolt.IndexedTriangle(index[a] ?? a, index[b] ?? b, index[c] ?? c, 0, t);
    triangles.push_back(tri);
    Jolt.destroy(tri);
  });
  // The constructor drops degenerate and duplicate triangles (Sanitize).
  const meshSettings = new Jolt.MeshShapeSettings(vertices, triangles, new Jolt.PhysicsMaterialList());
  meshSettings.mPerTriangleUserData = true;
  Jolt.destroy(vertices);
  Jolt.destroy(triangles);
  if (meshSettings.mIndexedTriangles.size() === 0) return; // nothing to hit: every sweep misses
  const result = meshSettings.Create();
  if (result.HasError()) fail(`scene \`${msg.name ?? ''}\`: MeshShape: ${result.GetError().c_str()}`);
  const mesh = result.Get();
  const position = new Jolt.RVec3(0, 0, 0), rotation = new Jolt.Quat(0, 0, 0, 1);
  const bcs = new Jolt.BodyCreationSettings(mesh, position, rotation, Jolt.EMotionType_Static, NON_MOVING);
  scene.body = bodies.CreateAndAddBody(bcs, Jolt.EActivation_DontActivate);
  scene.mesh = Jolt.castObject(mesh, Jolt.MeshShape);
  [position, rotation, bcs].forEach((o) => Jolt.destroy(o));
}

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const xyz = (v) => [v.GetX(), v.GetY(), v.GetZ()];

// Kind and feature of a contact point p on triangle (a, b, c), from its
// barycentric weights w[i] (of vertex i): two weights ~0 -> vertex i (the one
// near 1), one weight w[k] ~0 -> edge (k+1)%3 (joining k+1 and k+2), else face.
function classify(p, triangle) {
  return classifyWith(p, triangle, variant === 'loose_bary' ? LOOSE_BARY_EPS : BARY_EPS);
}

function classifyWith(p, [a, b, c], eps) {
  const n = cross(sub(b, a), sub(c, a)), nn = dot(n, n);
  const w = [dot(n, cross(sub(b, p), sub(c, p))) / nn, dot(n, cross(sub(c, p), sub(a, p))) / nn, 0];
  w[2] = 1 - w[0] - w[1];
  const zero = w.map((x) => x <= eps);
  const count = zero.filter(Boolean).length;
  if (count >= 2) return { kind: 'vertex', feature: w.indexOf(Math.max(...w)) };
  if (count === 1) return { kind: 'edge', feature: (zero.indexOf(true) + 1) % 3 };
  return { kind: 'face', feature: null };
}

// The SphereShape of a radius, made once and kept alive.
function sphereOf(radius) {
  let sphere = spheres.get(radius);
  if (!sphere) {
    sphere = new Jolt.SphereShape(radius);
    sphere.AddRef();
    spheres.set(radius, sphere);
  }
  return sphere;
}

// A contact query (`check --engine-contacts`): Jolt's own
// NarrowPhaseQuery::CollideShape of a SphereShape at the ball's centre
// against the mesh, every hit collected (one per triangle), with the query's
// contact distance as mMaxSeparationDistance. Jolt reports no feature for a
// contact, so none is given (the judge compares only what is given).
function contacts(msg) {
  const answer = { type: 'contacts', frame: msg.frame, ball: msg.ball, contacts: [] };
  if (!scene) fail(`the contact query of frame ${msg.frame}, ball ${msg.ball} arrived before any scene`);
  if (!scene.body) return answer;
  collideSettings.mMaxSeparationDistance = msg.distance ?? 0;
  const centre = new Jolt.RVec3(...msg.centre);
  const transform = Jolt.RMat44.prototype.sTranslation(centre);
  const collector = new Jolt.CollideShapeAllHitCollisionCollector();
  query.CollideShape(sphereOf(msg.radius), unitScale, transform, collideSettings, baseOffset, collector,
    bpFilter, objFilter, bodyFilter, shapeFilter);
  const hits = collector.get_mHits();
  for (let i = 0; i < hits.size(); i++) {
    const hit = hits.at(i);
    const triangle = scene.mesh.GetTriangleUserData(hit.mSubShapeID2);
    // The penetration axis points from the ball into the mesh: negate it.
    const axis = xyz(hit.mPenetrationAxis), len = Math.sqrt(dot(axis, axis));
    const contact = { triangle, point: xyz(hit.mContactPointOn2), separation: -hit.mPenetrationDepth };
    if (len > 0) contact.normal = axis.map((x) => -x / len);
    answer.contacts.push(contact);
  }
  [centre, transform, collector].forEach((o) => Jolt.destroy(o));
  return answer;
}

function sweep(msg) {
  const none = { frame: msg.frame, ball: msg.ball, alpha: 1, kind: 'none' };
  if (!scene) fail(`the sweep of frame ${msg.frame}, ball ${msg.ball} arrived before any scene`);
  if (!scene.body) return none;
  const radius = honourMargin ? msg.radius - scene.margin : msg.radius;
  lastRadius = msg.radius;
  const sphere = sphereOf(radius);
  const [p0, p1] = [msg.p0, msg.p1], d = sub(p1, p0);
  if (variant === 'glued') {
    const stuck = glued(msg, p0, d);
    if (stuck) return stuck;
  }
  const start = new Jolt.RVec3(...p0), direction = new Jolt.Vec3(...d);
  const transform = Jolt.RMat44.prototype.sTranslation(start);
  const cast = new Jolt.RShapeCast(sphere, unitScale, transform, direction);
  // Variant `first_hit`: every hit is collected and the one of the lowest
  // triangle index answered, as a walk that stops at its first hit would.
  const collector = variant === 'first_hit'
    ? new Jolt.CastShapeAllHitCollisionCollector()
    : new Jolt.CastShapeClosestHitCollisionCollector();
  query.CastShape(cast, castSettings, baseOffset, collector, bpFilter, objFilter, bodyFilter, shapeFilter);
  let answer = none;
  if (collector.HadHit()) {
    const hit = variant === 'first_hit' ? lowestTriangleHit(collector.get_mHits()) : collector.get_mHit();
    const triangle = scene.mesh.GetTriangleUserData(hit.mSubShapeID2);
    const contact = xyz(hit.mContactPointOn2); // on the mesh (base offset 0: world space)
    // Jolt's penetration axis points from the ball into the mesh: negate it.
    const axis = xyz(hit.mPenetrationAxis), len = Math.sqrt(dot(axis, axis));
    const normal = axis.map((x) => -x / len);
    const alpha = Math.min(Math.max(hit.mFraction, 0), 1);
    const { kind, feature } = classify(contact, scene.triangles[triangle].map((i) => scene.vertices[i]));
    answer = { frame: msg.frame, ball: msg.ball, alpha, kind, triangle, feature, normal, contact };
  }
  [start, direction, transform, cast, collector].forEach((o) => Jolt.destroy(o));
  return mistake(answer, p0, d);
}

// Of the hits of an all-hit collector, the one on the lowest triangle index.
function lowestTriangleHit(hits) {
  let best = null, bestTriangle = Infinity;
  for (let i = 0; i < hits.size(); i += 1) {
    const hit = hits.at(i), triangle = scene.mesh.GetTriangleUserData(hit.mSubShapeID2);
    if (triangle < bestTriangle) [best, bestTriangle] = [hit, triangle];
  }
  return best;
}

// The corners of triangle `t` of the scene, and its unit front normal.
const corners = (t) => scene.triangles[t].map((i) => scene.vertices[i]);
function faceNormal(t) {
  const [a, b, c] = corners(t), n = cross(sub(b, a), sub(c, a)), len = Math.sqrt(dot(n, n));
  return n.map((x) => x / len);
}

// The other triangle that has edge `e` of triangle `t` (its vertices
// e and e+1), or -1.
function neighbour(t, e) {
  const tri = scene.triangles[t], [u, v] = [tri[e], tri[(e + 1) % 3]];
  return scene.triangles.findIndex((o, k) => k !== t && o.includes(u) && o.includes(v));
}

// Variant `glued`: a ball that starts within its radius of a triangle's
// plane, over the triangle, and moves away from it (n · d > 0) is answered
// as a face hit at alpha 0 (a resting ball glued to the surface).
function glued(msg, p0, d) {
  for (let t = 0; t < scene.triangles.length; t += 1) {
    const [a] = corners(t), n = faceNormal(t), h = dot(n, sub(p0, a));
    if (!(dot(n, d) > 0 && Math.abs(h) <= msg.radius)) continue;
    const contact = p0.map((x, i) => x - h * n[i]);
    if (classifyWith(contact, corners(t), 0).kind !== 'face') continue;
    return { frame: msg.frame, ball: msg.ball, alpha: 0, kind: 'face', triangle: t, feature: null, normal: n, contact };
  }
  return null;
}

// `n` turned by `angle` radians about an axis perpendicular to it.
function tilt(n, angle) {
  const helper = Math.abs(n[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
  const t = cross(n, helper), len = Math.sqrt(dot(t, t));
  return n.map((x, i) => Math.cos(angle) * x + Math.sin(angle) * t[i] / len);
}

// The radius of the sweep an answer belongs to (kept by `sweep`).
let lastRadius = 0;
const radiusOf = () => lastRadius;

// The deliberate mistakes (variant `clean` has none).
function mistake(answer, p0, d) {
  if (answer.kind === 'none') return answer;
  switch (variant) {
    case 'late': return { ...answer, alpha: Math.min(answer.alpha * 1.002, 1) };
    case 'no_vertex': return answer.kind === 'vertex' ? { frame: answer.frame, ball: answer.ball, alpha: 1, kind: 'none' } : answer;
    case 'next_triangle': return answer.kind === 'face' ? { ...answer, triangle: (answer.triangle + 1) % scene.triangles.length } : answer;
    case 'centre_contact': return { ...answer, contact: p0.map((x, i) => x + answer.alpha * d[i]) };
    case 'flipped_edge_normal': return answer.kind === 'edge' ? { ...answer, normal: answer.normal.map((x) => -x) } : answer;
    // A face hit's normal turned by 1 degree (about an axis in the face's plane).
    case 'tilted_face_normal': return answer.kind === 'face' ? { ...answer, normal: tilt(answer.normal, Math.PI / 180) } : answer;
    // Normals never normalised: every one of length 0.5.
    case 'half_normal': return { ...answer, normal: answer.normal.map((x) => 0.5 * x) };
    // A face contact 1 % of the radius off the triangle's plane, toward the ball.
    case 'contact_off_plane': return answer.kind === 'face' ? { ...answer, contact: answer.contact.map((x, i) => x + 0.01 * radiusOf(answer) * answer.normal[i]) } : answer;
    // Every hit backed off by a skin of 1e-3 along the path.
    case 'skin': return { ...answer, alpha: Math.max(answer.alpha - 1e-3 / Math.sqrt(dot(d, d)), 0) };
    // At a convex edge whose faces meet below 30 degrees (Jolt's threshold
    // is 5), the face normal of the triangle hit instead of the contact normal.
    case 'wide_active_edges': return answer.kind === 'edge' && edgeAngle(answer) !== null && edgeAngle(answer) < 30
      ? { ...answer, normal: faceNormal(answer.triangle) } : answer;
    // At an edge shared with a coplanar triangle, the normal tilted by 10
    // degrees toward the edge (a ghost normal).
    case 'ghost_flat': return answer.kind === 'edge' && edgeAngle(answer) === 0 ? { ...answer, normal: ghost(answer) } : answer;
    // A lost leaf: in a mesh of more than 64 triangles (a tree of many
    // leaves), every hit on the second half of the triangles dropped.
    case 'lost_leaf': return scene.triangles.length > 64 && answer.triangle >= scene.triangles.length / 2
      ? { frame: answer.frame, ball: answer.ball, alpha: 1, kind: 'none' } : answer;
    default: return answer; // clean, back_faces, first_hit, loose_bary (in the cast), glued (before it)
  }
}

// At an edge hit, the angle in degrees between the normals of the two
// triangles that share the edge when it is convex, 0 when they are
// coplanar; null at a boundary or concave edge.
function edgeAngle(answer) {
  const other = neighbour(answer.triangle, answer.feature);
  if (other < 0) return null;
  const [n, m] = [faceNormal(answer.triangle), faceNormal(other)];
  const cos = Math.min(Math.max(dot(n, m), -1), 1);
  if (cos >= 1 - 1e-12) return 0;
  // Convex: the other triangle's far corner lies behind this one's plane.
  const far = corners(other).find((v) => !corners(answer.triangle).some((w) => w.every((x, i) => x === v[i])));
  const convex = dot(n, sub(far, corners(answer.triangle)[0])) < 0;
  return convex ? Math.acos(cos) * 180 / Math.PI : null;
}

// The normal of an edge hit turned by 10 degrees toward the edge, within
// the plane through the normal and the edge's outward direction.
function ghost(answer) {
  const tri = corners(answer.triangle), e = answer.feature;
  const [u, v] = [tri[e], tri[(e + 1) % 3]], n = faceNormal(answer.triangle);
  let out = cross(sub(v, u), n);
  const len = Math.sqrt(dot(out, out));
  out = out.map((x) => x / len);
  const angle = 10 * Math.PI / 180;
  return n.map((x, i) => Math.cos(angle) * x + Math.sin(angle) * out[i]);
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
