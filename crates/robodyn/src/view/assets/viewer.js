// robodyn view: draws a robot from its Khalil–Kleinfinger geometry (the scene robodyn embeds as
// JSON in this page), with the forward kinematics computed here in double precision:
//   iT_j = Rot(z, gamma) Trans(z, b) Rot(x, alpha) Trans(x, d) Rot(z, theta) Trans(z, r),
// q_j added to theta (sigma = 0) or r (sigma = 1); fixed frames (sigma = 2) have no variable.
// Frame j's objects are children of one group whose matrix is 0T_j, so what is drawn is what
// window.robodynView.frameTransforms() reports (the browser tests compare it with robodyn).
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/OrbitControls.js';
import { CSS2DRenderer, CSS2DObject } from 'three/addons/CSS2DRenderer.js';
import { STLLoader } from 'three/addons/STLLoader.js';

const S = JSON.parse(document.getElementById('robodyn-scene').textContent);
const NJ = S.nj, NF = S.nf, F = S.frames; // F[j - 1] is frame j
const q = S.pose.q.slice();               // values of frames 1..NJ (cut joints included)
const $ = (id) => document.getElementById(id);
const COLORS = { x: 0xd62728, z: 0x1f5fd6, rev: 0xe8a317, pri: 0x2ca02c, fixed: 0x888888,
  cut: 0xd63ca0, link: 0x9aa0a6, loop: 0xe07ac0, base: 0x555555, g: 0x7b3fb5, halo: 0xffd400 };

// ---------------------------------------------------------------- forward kinematics
// A transform is { R: 3x3 row-major (9 numbers), p: [x, y, z] }.
function local(f, qj) {
  const [gamma, b, alpha, d, theta0, r0] = f.values;
  const theta = theta0 + (f.sigma === 0 ? qj : 0), r = r0 + (f.sigma === 1 ? qj : 0);
  const cg = Math.cos(gamma), sg = Math.sin(gamma), ca = Math.cos(alpha), sa = Math.sin(alpha);
  const ct = Math.cos(theta), st = Math.sin(theta);
  const A = [cg, -sg * ca, sg * sa, sg, cg * ca, -cg * sa, 0, sa, ca]; // Rz(gamma) Rx(alpha)
  const R = [];
  for (let i = 0; i < 3; i++) R.push(A[3 * i] * ct + A[3 * i + 1] * st, A[3 * i + 1] * ct - A[3 * i] * st, A[3 * i + 2]);
  return { R, p: [d * cg + r * sg * sa, d * sg - r * cg * sa, r * ca + b] }; // eq. 10.18
}
function compose(a, b) {
  const R = [], p = [];
  for (let i = 0; i < 3; i++) {
    for (let k = 0; k < 3; k++) R.push(a.R[3 * i] * b.R[k] + a.R[3 * i + 1] * b.R[3 + k] + a.R[3 * i + 2] * b.R[6 + k]);
    p.push(a.p[i] + a.R[3 * i] * b.p[0] + a.R[3 * i + 1] * b.p[1] + a.R[3 * i + 2] * b.p[2]);
  }
  return { R, p };
}
const IDENTITY = { R: [1, 0, 0, 0, 1, 0, 0, 0, 1], p: [0, 0, 0] };
function forward(values) { // 0T_j for j = 0..NF
  const T = [IDENTITY];
  for (let j = 1; j <= NF; j++) T.push(compose(T[F[j - 1].ant], local(F[j - 1], j <= NJ ? values[j - 1] : 0)));
  return T;
}
const toMatrix = (t, m = new THREE.Matrix4()) =>
  m.set(t.R[0], t.R[1], t.R[2], t.p[0], t.R[3], t.R[4], t.R[5], t.p[1], t.R[6], t.R[7], t.R[8], t.p[2], 0, 0, 0, 1);

// ---------------------------------------------------------------- sizes, renderer, camera
const T0 = forward(q);
const V = (a) => new THREE.Vector3(a[0], a[1], a[2]);
const box = new THREE.Box3();
T0.forEach((t) => box.expandByPoint(V(t.p)));
if (S.trajectory) { // the view frames the whole motion (up to 500 samples of it)
  const rows = S.trajectory.q, step = Math.max(1, Math.floor(rows.length / 500));
  for (let i = 0; i < rows.length; i += step) forward(rows[i]).forEach((t) => box.expandByPoint(V(t.p)));
}
const L = Math.max(box.getSize(new THREE.Vector3()).length(), 0.05); // robot size (m)
const links = F.map((f) => V(T0[f.j].p).distanceTo(V(T0[f.ant].p))).filter((x) => x > 1e-6 * L).sort((a, b) => a - b);
const AX = Math.min(Math.max(0.6 * (links[links.length >> 1] || L), 0.035 * L), 0.1 * L); // axis length
const R_AX = 0.045 * AX, R_LINK = 0.06 * AX, R_JOINT = 0.17 * AX, H_JOINT = 0.5 * AX;

const picture = !!S.picture;
if (picture) document.body.classList.add('picture');
const view = $('view');
let renderer;
try {
  renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
} catch (e) {
  showMessage(`WebGL is not available in this browser, the 3D view cannot be drawn (${e.message}).`);
  throw e;
}
renderer.setPixelRatio(window.devicePixelRatio);
view.appendChild(renderer.domElement);
const labels = new CSS2DRenderer();
labels.domElement.style.position = 'absolute';
labels.domElement.style.top = '0';
labels.domElement.style.pointerEvents = 'none';
view.appendChild(labels.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(0xffffff);
scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8a8a, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
scene.add(sun);
const g = V(S.gravity), gNorm = g.length();
const up = gNorm > 0 ? g.clone().negate().normalize() : new THREE.Vector3(0, 0, 1);
const camera = new THREE.PerspectiveCamera(35, 1, L / 1000, L * 100);
camera.up.copy(up);
const controls = new OrbitControls(camera, renderer.domElement);
controls.addEventListener('change', requestRender);

// A view from the side where the robot is widest: the horizontal direction of least spread of
// the frame origins, turned 30 degrees and raised.
function defaultCamera() {
  let e1 = new THREE.Vector3(1, 0, 0).projectOnPlane(up);
  if (e1.length() < 1e-6) e1 = new THREE.Vector3(0, 1, 0).projectOnPlane(up);
  e1.normalize();
  const e2 = new THREE.Vector3().crossVectors(up, e1);
  let cxx = 0, cyy = 0, cxy = 0;
  T0.forEach((t) => {
    const p = V(t.p).sub(center), a = p.dot(e1), b = p.dot(e2);
    cxx += a * a; cyy += b * b; cxy += a * b;
  });
  const major = 0.5 * Math.atan2(2 * cxy, cxx - cyy);
  let m = e1.clone().multiplyScalar(-Math.sin(major)).add(e2.clone().multiplyScalar(Math.cos(major)));
  if (m.dot(e1.clone().sub(e2.clone().multiplyScalar(0.6))) < 0) m.negate();
  const dir = m.clone().add(new THREE.Vector3().crossVectors(up, m).multiplyScalar(0.55)).add(up.clone().multiplyScalar(0.35)).normalize();
  const dist = (0.46 * VIEW) / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
  camera.position.copy(center).addScaledVector(dir, dist);
  controls.target.copy(center);
  controls.update();
  sun.position.copy(dir).add(up).multiplyScalar(VIEW * 3);
  return dir;
}

// ---------------------------------------------------------------- drawing helpers
const material = (color, extra = {}) => new THREE.MeshStandardMaterial({ color, roughness: 0.55, metalness: 0.05, ...extra });
const Y = new THREE.Vector3(0, 1, 0);
function cylinder(a, b, radius, mat) { // a solid segment from a to b (Vector3)
  const d = b.clone().sub(a), len = d.length();
  const mesh = new THREE.Mesh(new THREE.CylinderGeometry(radius, radius, 1, 16), mat);
  mesh.scale.set(1, Math.max(len, 1e-9), 1);
  mesh.quaternion.setFromUnitVectors(Y, len > 0 ? d.normalize() : Y);
  mesh.position.copy(a).add(b).multiplyScalar(0.5);
  return mesh;
}
function arrow(dir, length, radius, color) {
  const group = new THREE.Group(), mat = material(color);
  const tip = dir.clone().multiplyScalar(length), base = dir.clone().multiplyScalar(length * 0.78);
  group.add(cylinder(new THREE.Vector3(), base, radius, mat));
  const head = new THREE.Mesh(new THREE.ConeGeometry(radius * 2.6, length * 0.22, 16), mat);
  head.quaternion.setFromUnitVectors(Y, dir);
  head.position.copy(base).add(tip).multiplyScalar(0.5);
  group.add(head);
  return group;
}
function dashed(dir, length, color) {
  const geom = new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(), dir.clone().multiplyScalar(length)]);
  const line = new THREE.Line(geom, new THREE.LineDashedMaterial({ color, dashSize: length / 8, gapSize: length / 12 }));
  line.computeLineDistances();
  return line;
}
function label(html, cls, position) {
  const el = document.createElement('div');
  el.className = `label ${cls}`;
  el.innerHTML = html;
  const obj = new CSS2DObject(el);
  obj.position.copy(position);
  return obj;
}

// ---------------------------------------------------------------- the robot
const layers = { frames: [], labels: [], sketch: [], meshes: [], com: [] };
const frameObj = [];      // frameObj[j]: group at 0T_j (j = 0: the base)
const pickable = [];      // joint solids, for the frame under the mouse
const axisLabels = [];    // { obj, axis, j, leader }: the x_j and z_j labels
const rSegments = [];     // [frame, mesh]: the r segments of prismatic joints (length varies)
for (let jj = 0; jj <= NF; jj++) {
  const grp = new THREE.Group();
  grp.matrixAutoUpdate = false;
  scene.add(grp);
  frameObj.push(grp);
}
const ex = new THREE.Vector3(1, 0, 0), ez = new THREE.Vector3(0, 0, 1);
function addAxes(jj, kind) {
  const grp = frameObj[jj], thin = kind === 'fixed' ? 0.6 : 1;
  for (const [axis, dir, color] of [['x', ex, COLORS.x], ['z', ez, COLORS.z]]) {
    const obj = kind === 'twin' ? dashed(dir, AX * 1.15, color) : arrow(dir, AX, R_AX * thin, color);
    grp.add(obj);
    layers.frames.push(obj);
    const lab = label(`${axis}<sub>${jj}</sub>`, `${axis}${kind === 'twin' ? ' twin' : ''}`, dir.clone().multiplyScalar(AX * 1.12));
    grp.add(lab);
    layers.labels.push(lab);
    axisLabels.push({ obj: lab, axis, j: jj, leader: null });
  }
}
function addJoint(f) {
  const grp = frameObj[f.j];
  let mesh;
  if (f.sigma === 2) {
    mesh = new THREE.Mesh(new THREE.BoxGeometry(R_JOINT, R_JOINT, R_JOINT), material(f.kind === 'twin' ? COLORS.cut : COLORS.fixed, f.kind === 'twin' ? { transparent: true, opacity: 0.5 } : {}));
  } else if (f.sigma === 1) {
    mesh = new THREE.Mesh(new THREE.BoxGeometry(1.4 * R_JOINT, 1.4 * R_JOINT, 1.4 * H_JOINT), material(f.kind === 'cut' ? COLORS.cut : COLORS.pri));
  } else {
    mesh = new THREE.Mesh(new THREE.CylinderGeometry(R_JOINT, R_JOINT, H_JOINT, 24), material(f.kind === 'cut' ? COLORS.cut : COLORS.rev));
    mesh.quaternion.setFromUnitVectors(Y, ez);
  }
  mesh.userData.frame = f.j;
  grp.add(mesh);
  pickable.push(mesh);
  layers.sketch.push(mesh);
}
// The link drawn along the parameters: in R_i, O_i -> (0, 0, b) along z_i -> + d along the common
// normal Rot(z, gamma) x_i; then in R_j the segment r along z_j ending at O_j.
function addLink(f) {
  const [gamma, b, , d, , r0] = f.values;
  const mat = material(f.kind === 'cut' || f.kind === 'twin' ? COLORS.loop : COLORS.link);
  const o = new THREE.Vector3(), p1 = new THREE.Vector3(0, 0, b), p2 = new THREE.Vector3(d * Math.cos(gamma), d * Math.sin(gamma), b);
  for (const [a, c] of [[o, p1], [p1, p2]]) {
    if (a.distanceTo(c) > 1e-9) {
      const seg = cylinder(a, c, R_LINK, mat);
      frameObj[f.ant].add(seg);
      layers.sketch.push(seg);
    }
  }
  const seg = cylinder(new THREE.Vector3(0, 0, -1), new THREE.Vector3(), R_LINK, mat);
  frameObj[f.j].add(seg);
  layers.sketch.push(seg);
  rSegments.push([f, seg, r0]);
}
// The centre of mass of link j (a small dark ball); a terminal link (no frame on it) is drawn
// from O_j to it, so that its extent shows.
function addMass(f) {
  if (!f.com) return;
  const g = V(f.com), ball = new THREE.Mesh(new THREE.SphereGeometry(0.7 * R_JOINT, 16, 12), material(0x333333));
  ball.position.copy(g);
  frameObj[f.j].add(ball);
  layers.com.push(ball);
  if (!F.some((c) => c.ant === f.j) && g.length() > 1e-9) {
    const seg = cylinder(new THREE.Vector3(), g, 0.7 * R_LINK, material(COLORS.link));
    frameObj[f.j].add(seg);
    layers.sketch.push(seg);
  }
}
addAxes(0, 'base');
{
  const base = new THREE.Mesh(new THREE.CylinderGeometry(2.4 * R_JOINT, 2.8 * R_JOINT, 0.8 * R_JOINT, 32), material(COLORS.base));
  base.quaternion.setFromUnitVectors(Y, ez);
  base.position.set(0, 0, -0.4 * R_JOINT - 0.5 * H_JOINT);
  frameObj[0].add(base);
  layers.sketch.push(base);
  const lab = label('R<sub>0</sub>', 'frame', new THREE.Vector3(-0.25 * AX, -0.25 * AX, 0));
  frameObj[0].add(lab);
  layers.labels.push(lab);
}
F.forEach((f) => { addAxes(f.j, f.kind); addJoint(f); addLink(f); addMass(f); });

// the gravity vector, beside the robot as the first view sees it (dir: towards the camera)
function gravityArrow(dir) {
  if (!(gNorm > 0)) return;
  const right = new THREE.Vector3().crossVectors(up, dir).normalize();
  const reach = Math.max(...corners.map((c) => c.clone().sub(center).dot(right)));
  const gd = g.clone().normalize(), length = 0.16 * VIEW;
  const start = center.clone().addScaledVector(right, reach + 0.06 * VIEW).addScaledVector(up, 0.5 * length);
  const ga = arrow(gd, length, 0.006 * VIEW, COLORS.g);
  ga.position.copy(start);
  scene.add(ga);
  scene.add(label(`g = ${+gNorm.toFixed(3)} m/s²`, 'g', start.clone().addScaledVector(gd, 1.18 * length)));
}

// URDF visuals: STL meshes and shapes, in the frame of their link
const visuals = (S.visuals && S.visuals.items) || [];
const meshMaterials = [], brokenMeshes = [];
if (visuals.length) {
  const loader = new STLLoader();
  for (const v of visuals) {
    let geom;
    if (v.shape === 'stl') {
      try {
        geom = loader.parse(Uint8Array.from(atob(v.data), (c) => c.charCodeAt(0)).buffer);
      } catch (e) {
        brokenMeshes.push(`${v.file}: not a valid STL file (${e.message}); its link is drawn as the sketch`);
        continue;
      }
    } else if (v.shape === 'box') {
      geom = new THREE.BoxGeometry(...v.size);
    } else if (v.shape === 'cylinder') {
      geom = new THREE.CylinderGeometry(v.radius, v.radius, v.length, 24).rotateX(Math.PI / 2);
    } else {
      geom = new THREE.SphereGeometry(v.radius, 24, 16);
    }
    const color = new THREE.Color(0xb9bcc0);
    if (v.color) color.setRGB(v.color[0], v.color[1], v.color[2], THREE.SRGBColorSpace);
    const mat = material(color, { roughness: 0.7, side: THREE.DoubleSide });
    meshMaterials.push(mat);
    const mesh = new THREE.Mesh(geom, mat);
    mesh.matrixAutoUpdate = false;
    const o = v.origin, s = v.scale || [1, 1, 1];
    mesh.matrix.set(o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7], o[8], o[9], o[10], o[11], 0, 0, 0, 1)
      .multiply(new THREE.Matrix4().makeScale(s[0], s[1], s[2]));
    frameObj[v.frame].add(mesh);
    layers.meshes.push(mesh);
    geom.computeBoundingBox(); // the view frames the meshes too
    box.union(geom.boundingBox.clone().applyMatrix4(toMatrix(T0[v.frame]).multiply(mesh.matrix)));
  }
}

// the ground, perpendicular to gravity, under the robot
const corners = [0, 1, 2, 3, 4, 5, 6, 7].map((k) => new THREE.Vector3(k & 1 ? box.max.x : box.min.x, k & 2 ? box.max.y : box.min.y, k & 4 ? box.max.z : box.min.z));
const center = box.getCenter(new THREE.Vector3()), VIEW = Math.max(box.getSize(new THREE.Vector3()).length(), L);
const groundLevel = Math.min(...corners.map((c) => c.dot(up))) - 0.5 * H_JOINT;
const grid = new THREE.GridHelper(Math.ceil(2.4 * VIEW * 10) / 10, 12, 0xc8c8c8, 0xe4e4e4);
grid.quaternion.setFromUnitVectors(Y, up);
grid.position.copy(center).addScaledVector(up, groundLevel - center.dot(up));
scene.add(grid);

// highlight: a halo at the frame's origin, its labels and its table row
const halo = new THREE.Mesh(new THREE.SphereGeometry(2.2 * R_JOINT, 24, 16), new THREE.MeshBasicMaterial({ color: COLORS.halo, transparent: true, opacity: 0.45, depthTest: false }));
halo.visible = false;
halo.renderOrder = 10;
scene.add(halo);
let highlighted = -1;
function highlight(jj) {
  if (jj === highlighted) return;
  if (highlighted >= 0) document.querySelectorAll('.hl').forEach((el) => el.classList.remove('hl'));
  highlighted = jj;
  halo.visible = jj >= 0;
  if (jj >= 0) {
    frameObj[jj].add(halo);
    axisLabels.filter((l) => l.j === jj).forEach((l) => (l.leader || l).obj.element.classList.add('hl'));
    const row = $(`row-${jj}`), sl = $(`slider-${jj}`);
    if (row) row.classList.add('hl');
    if (sl) sl.classList.add('hl');
  }
  requestRender();
}

// ---------------------------------------------------------------- pose, panels
const fmt = (x, d = 4) => (Math.abs(x) < 5e-13 ? '0' : (+x.toFixed(d)).toString());
function valueText(jj) {
  const x = q[jj - 1];
  return F[jj - 1].sigma === 1 ? `${fmt(x)} m` : `${fmt(x)} rad (${fmt((x * 180) / Math.PI, 1)}°)`;
}
const m4 = new THREE.Matrix4();
function update() {
  const T = forward(q);
  for (let jj = 0; jj <= NF; jj++) {
    toMatrix(T[jj], frameObj[jj].matrix);
    frameObj[jj].matrixWorldNeedsUpdate = true;
  }
  for (const [f, seg, r0] of rSegments) { // r along z_j, ending at O_j
    const r = r0 + (f.sigma === 1 ? q[f.j - 1] : 0);
    seg.visible = Math.abs(r) > 1e-9 && layers.sketch.visible !== false;
    seg.scale.y = Math.max(Math.abs(r), 1e-9);
    seg.position.set(0, 0, -r / 2);
  }
  mergeLabels();
  for (let jj = 1; jj <= NJ; jj++) {
    const cell = $(`q-${jj}`);
    if (cell) cell.textContent = F[jj - 1].sigma === 2 ? '' : fmt(q[jj - 1]);
    const s = $(`slider-${jj}`);
    if (s) { s.querySelector('input').value = q[jj - 1]; s.querySelector('.value').textContent = valueText(jj); }
  }
  requestRender();
}

// Axis labels at the same place (frames sharing an origin and an axis, a cut joint on its twin)
// become one label listing the frames: x<sub>9,10</sub>.
function mergeLabels() {
  const on = layers.labels.visible !== false, at = new THREE.Vector3(), leaders = [];
  for (const l of axisLabels) {
    at.copy(l.obj.position).applyMatrix4(frameObj[l.j].matrix);
    const lead = leaders.find((m) => m.axis === l.axis && m.at.distanceTo(at) < 0.04 * AX);
    l.leader = lead ? lead.label : null;
    l.obj.visible = on && !lead;
    if (lead) lead.frames.push(l.j);
    else leaders.push({ axis: l.axis, at: at.clone(), label: l, frames: [l.j] });
  }
  for (const m of leaders) m.label.obj.element.innerHTML = `${m.axis}<sub>${m.frames.join(',')}</sub>`;
}

function buildPanels() {
  $('robot-name').textContent = S.robot;
  const kinds = { tree: 0, fixed: 0, cut: 0, twin: 0 };
  F.forEach((f) => kinds[f.kind]++);
  $('summary').textContent = `NL = ${S.nl}, NJ = ${NJ}, NF = ${NF}: ${S.coordinates.length} movable joints` +
    (S.closed ? `, ${S.loops.length} loop(s) (cut joints ${S.loops.map((l) => l.cut).join(', ')})` : ', tree') +
    (kinds.fixed ? `, ${kinds.fixed} fixed frame(s)` : '') +
    (S.trajectory ? `. Trajectory: ${S.trajectory.t.length} samples, t = ${fmt(S.trajectory.t[0])} to ${fmt(S.trajectory.t[S.trajectory.t.length - 1])} s.` : `. Pose: ${S.pose.note}.`);
  $('caption').textContent = picture ? S.robot : '';
  // toggles
  const toggles = [['frames', 'frames', true], ['labels', 'labels', NF <= 30], ['sketch', 'links and joints', true],
    ['com', 'centres of mass', NF <= 30]];
  // meshes translucent in the page (the frames inside show), opaque in a picture
  if (visuals.length) toggles.push(['meshes', 'meshes', true], ['xray', 'translucent meshes', !picture]);
  toggles.push(['grid', 'ground grid', true]);
  for (const [key, text, on] of toggles) {
    const lab = document.createElement('label');
    lab.innerHTML = `<input type="checkbox" id="toggle-${key}" ${on ? 'checked' : ''}> ${text}`;
    $('toggles').appendChild(lab);
    lab.querySelector('input').addEventListener('change', (e) => setToggle(key, e.target.checked));
    setToggle(key, on);
  }
  // sliders
  $('joint-note').textContent = S.closed
    ? 'Closed chain: the passive joints follow from loop closure (done by robodyn for this page), so the values are shown but do not move; give other actuated values with --q, or a trajectory.'
    : 'Drag to move a joint (limits from the robot file when it gives them).';
  for (const jj of S.coordinates) {
    const f = F[jj - 1], lim = f.limits;
    let [lo, hi] = lim || (f.sigma === 1 ? [-L, L] : [-Math.PI, Math.PI]);
    lo = Math.min(lo, q[jj - 1]); hi = Math.max(hi, q[jj - 1]);
    const row = document.createElement('div');
    row.className = 'slider';
    row.id = `slider-${jj}`;
    row.innerHTML = `<span class="name" title="${f.name}">q${jj} ${f.name === `j${jj}` ? '' : f.name}${f.mu ? '' : ' (passive)'}</span>` +
      `<input type="range" min="${lo}" max="${hi}" step="${(hi - lo) / 2000}" value="${q[jj - 1]}" ${S.closed ? 'disabled' : ''}><span class="value"></span>`;
    row.querySelector('input').addEventListener('input', (e) => { pause(); q[jj - 1] = +e.target.value; update(); });
    row.addEventListener('mouseenter', () => highlight(jj));
    row.addEventListener('mouseleave', () => highlight(-1));
    $('sliders').appendChild(row);
  }
  // frames table
  const head = ['j', 'name', 'a(j)', 'σ', 'μ', 'γ', 'b', 'α', 'd', 'θ', 'r', 'q'];
  const table = $('frame-table');
  table.innerHTML = `<thead><tr>${head.map((h) => `<th>${h}</th>`).join('')}</tr></thead>`;
  const body = document.createElement('tbody');
  for (const f of F) {
    const tr = document.createElement('tr');
    tr.id = `row-${f.j}`;
    tr.className = f.kind;
    tr.title = `${f.kind === 'tree' ? 'joint' : f.kind === 'cut' ? 'cut joint' : f.kind === 'twin' ? 'twin frame of the cut joint' : 'fixed frame'}${f.link ? `, link ${f.link}` : ''}`;
    const cells = [f.j, f.name, f.ant, f.sigma, f.mu, ...f.text, ''];
    tr.innerHTML = cells.map((c, k) => `<td class="${k === 1 ? 'name' : ''}" ${k >= 5 && k < 11 ? `title="${f.values[k - 5]}"` : ''}>${c}</td>`).join('');
    tr.lastChild.id = `q-${f.j}`;
    tr.addEventListener('mouseenter', () => highlight(f.j));
    tr.addEventListener('mouseleave', () => highlight(-1));
    body.appendChild(tr);
  }
  table.appendChild(body);
  // notes
  const notes = [...(S.notes || [])];
  S.loops.forEach((l) => notes.push(`Loop of cut joint ${l.cut} (links ${l.link_i} and ${l.link_j}, twin frame ${l.twin}): frames ${l.cut} and ${l.twin} are ${l.gap.toExponential(1)} m and ${l.angle.toExponential(1)} rad apart${l.gap < 1e-6 && l.angle < 1e-6 ? ' (closed)' : ' (OPEN)'}.`));
  if (S.visuals) notes.push(...S.visuals.notes, ...brokenMeshes, `${visuals.length} visual(s) embedded from the URDF.`);
  if (S.trajectory) notes.push(...S.trajectory.notes);
  for (const n of notes) { const li = document.createElement('li'); li.textContent = n; $('note-list').appendChild(li); }
}
function setToggle(key, on) {
  if (key === 'grid') grid.visible = on;
  else if (key === 'xray') meshMaterials.forEach((m) => { m.transparent = on; m.opacity = on ? 0.45 : 1; m.depthWrite = !on; m.needsUpdate = true; });
  else {
    layers[key].forEach((o) => { o.visible = on; });
    layers[key].visible = on;
    if (key === 'sketch' || key === 'labels') update();
  }
  requestRender();
}

// ---------------------------------------------------------------- trajectory
const TR = S.trajectory;
let sample = 0, playing = false, simTime = 0, lastWall = 0;
function setSample(i) {
  sample = Math.max(0, Math.min(TR.t.length - 1, i));
  for (let jj = 0; jj < NJ; jj++) q[jj] = TR.q[sample][jj];
  $('time').value = sample;
  $('time-label').textContent = `t = ${fmt(TR.t[sample], 4)} s (${sample + 1}/${TR.t.length})`;
  update();
  drawPlot();
}
function setTime(t) { // the last sample at or before t
  let lo = 0, hi = TR.t.length - 1;
  while (lo < hi) { const mid = (lo + hi + 1) >> 1; if (TR.t[mid] <= t) lo = mid; else hi = mid - 1; }
  simTime = t;
  setSample(lo);
}
function tick(wall) {
  if (!playing) return;
  const dt = lastWall ? Math.min((wall - lastWall) / 1000, 0.1) : 0; // (no jump after a pause of the tab)
  lastWall = wall;
  let t = simTime + dt * +$('speed').value;
  if (t > TR.t[TR.t.length - 1]) t = TR.t[0]; // loop
  setTime(t);
  requestAnimationFrame(tick);
}
function play() { if (!TR || playing) return; playing = true; lastWall = 0; $('play').textContent = 'Pause'; requestAnimationFrame(tick); }
function pause() { if (!TR) return; playing = false; $('play').textContent = 'Play'; }
function drawPlot() {
  const c = $('plot'), dpr = window.devicePixelRatio || 1;
  const w = c.clientWidth, h = c.clientHeight;
  if (c.width !== w * dpr) { c.width = w * dpr; c.height = h * dpr; }
  const ctx = c.getContext('2d');
  ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
  ctx.clearRect(0, 0, w, h);
  const units = [...new Set(TR.plots.map((p) => p.unit))];
  const t0 = TR.t[0], t1 = TR.t[TR.t.length - 1], ph = h / units.length;
  const X = (t) => 62 + ((t - t0) / (t1 - t0 || 1)) * (w - 74);
  const palette = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'];
  ctx.font = '11px system-ui, sans-serif';
  units.forEach((unit, u) => {
    const plots = TR.plots.map((p, k) => [p, k]).filter(([p]) => p.unit === unit);
    let lo = Infinity, hi = -Infinity;
    for (const [p] of plots) for (const row of TR.q) { lo = Math.min(lo, row[p.frame - 1]); hi = Math.max(hi, row[p.frame - 1]); }
    if (hi - lo < 1e-12) { lo -= 0.5; hi += 0.5; }
    const top = u * ph + 8, bottom = (u + 1) * ph - 16;
    const Yp = (x) => bottom - ((x - lo) / (hi - lo)) * (bottom - top);
    ctx.strokeStyle = '#ccc'; ctx.fillStyle = '#555';
    ctx.strokeRect(62, top, w - 74, bottom - top);
    ctx.fillText(`${fmt(hi, 3)} ${unit}`, 2, top + 9);
    ctx.fillText(`${fmt(lo, 3)} ${unit}`, 2, bottom);
    if (u === units.length - 1) { ctx.fillText(`${fmt(t0, 3)} s`, 62, bottom + 12); ctx.fillText(`${fmt(t1, 3)} s`, w - 60, bottom + 12); }
    plots.forEach(([p, k], n) => {
      ctx.strokeStyle = ctx.fillStyle = palette[k % palette.length];
      ctx.beginPath();
      TR.q.forEach((row, i) => { const x = X(TR.t[i]), y = Yp(row[p.frame - 1]); if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y); });
      ctx.stroke();
      ctx.fillText(p.label, 68 + 70 * n, top + 11);
    });
  });
  ctx.strokeStyle = '#000';
  ctx.beginPath(); ctx.moveTo(X(TR.t[sample]), 0); ctx.lineTo(X(TR.t[sample]), h); ctx.stroke();
}
function buildPlayer() {
  $('player').hidden = false;
  $('time').max = TR.t.length - 1;
  $('time').addEventListener('input', (e) => { pause(); simTime = TR.t[+e.target.value]; setSample(+e.target.value); });
  $('play').addEventListener('click', () => (playing ? pause() : play()));
  const seek = (e) => {
    const r = $('plot').getBoundingClientRect();
    const t0 = TR.t[0], t1 = TR.t[TR.t.length - 1];
    pause();
    setTime(t0 + ((e.clientX - r.left - 62) / (r.width - 74)) * (t1 - t0));
  };
  $('plot').addEventListener('pointerdown', seek);
  $('plot').addEventListener('pointermove', (e) => { if (e.buttons) seek(e); });
}

// ---------------------------------------------------------------- rendering, picking
let renderQueued = false;
function render() {
  renderQueued = false;
  renderer.render(scene, camera);
  labels.render(scene, camera);
}
function requestRender() {
  if (!renderQueued && renderer) { renderQueued = true; requestAnimationFrame(render); }
}
function resize() {
  const w = picture ? S.picture.width : view.clientWidth, h = picture ? S.picture.height : view.clientHeight;
  renderer.setSize(w, h);
  labels.setSize(w, h);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
  if (TR) drawPlot();
  render();
}
const ray = new THREE.Raycaster(), pointer = new THREE.Vector2();
renderer.domElement.addEventListener('pointermove', (e) => {
  const r = renderer.domElement.getBoundingClientRect();
  pointer.set(((e.clientX - r.left) / r.width) * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1);
  ray.setFromCamera(pointer, camera);
  const hit = ray.intersectObjects(pickable.filter((o) => o.visible), false)[0];
  highlight(hit ? hit.object.userData.frame : -1);
  if (hit) $(`row-${hit.object.userData.frame}`).scrollIntoView({ block: 'nearest' });
});
function showMessage(text) { const m = $('message'); m.textContent = text; m.hidden = false; }
window.addEventListener('error', (e) => showMessage(`Error in the page: ${e.message}`));

buildPanels();
gravityArrow(defaultCamera());
if (TR) { buildPlayer(); setSample(0); }
update();
window.addEventListener('resize', resize);
resize();

// For tests and scripts: what is drawn, read from the scene's objects.
window.robodynView = {
  ready: true,
  frameTransforms() { // 0T_j for j = 1..NF, 4x4 row-major, from the drawn groups
    scene.updateMatrixWorld(true);
    return frameObj.slice(1).map((o) => { const e = o.matrixWorld.elements; return [0, 4, 8, 12, 1, 5, 9, 13, 2, 6, 10, 14, 3, 7, 11, 15].map((k) => e[k]); });
  },
  frameOrigins() { return this.frameTransforms().map((m) => [m[3], m[7], m[11]]); },
  setJoints(values) { S.coordinates.forEach((jj, k) => { q[jj - 1] = values[k]; }); update(); render(); },
  joints() { return S.coordinates.map((jj) => q[jj - 1]); },
  samples() { return TR ? TR.t.length : 0; },
  duration() { return TR ? TR.t[TR.t.length - 1] - TR.t[0] : 0; },
  sample() { return sample; },
  time() { return TR ? TR.t[sample] : null; },
  setTime(t) { setTime(t); render(); },
  play, pause,
  playing() { return playing; },
  highlight(jj) { highlight(jj); render(); },
  render,
};
