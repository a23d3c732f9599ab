// skelgraph viewer page: draws the frames the viewer component streams on /ws
// (message format: components/viewer/README.md). What it has drawn is counted
// in window.skelgraphViewer, which the browser test reads.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

// Joint order of msg::JointId; bones between them.
const BONES = [[0, 1], [1, 2], [1, 3], [3, 4], [4, 5], [1, 6], [6, 7], [7, 8],
               [2, 9], [9, 10], [10, 11], [2, 12], [12, 13], [13, 14], [9, 12]];
const PALETTE = [0x4f9dff, 0xff6bd6, 0x3fd6c6, 0xffd04f, 0xb08cff, 0xff9f43];
const FIXED_COLOURS = { fused: 0xff7f2a, truth: 0x5fdf5f };

const stats = {
  connected: false, framesReceived: 0, framesDrawn: 0, fps: 0, lastSeq: 0, paused: false,
  drawn: { skeletons: 0, joints: 0, list: [] }, sensors: 0, gestures: [], drawnGestures: { rays: 0, targets: 0 },
  errors: [], replies: [], players: [], drawnRobots: [],
};
window.skelgraphViewer = stats;

// --- three.js scene -------------------------------------------------------
const container = document.getElementById('view');
// Antialiasing costs a software renderer (SwiftShader, llvmpipe: no GPU) half its
// frame rate; with a GPU it is nearly free.
function glRenderer() {
  const gl = document.createElement('canvas').getContext('webgl2');
  const info = gl && gl.getExtension('WEBGL_debug_renderer_info');
  return info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
}
stats.gl = glRenderer();
stats.software = /swiftshader|llvmpipe|softpipe|software/i.test(stats.gl);
const renderer = new THREE.WebGLRenderer({ antialias: !stats.software });
renderer.setPixelRatio(window.devicePixelRatio);
container.appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x15181d);
const camera = new THREE.PerspectiveCamera(50, 1, 0.05, 100);
camera.position.set(3.4, 2.6, 3.4);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 1.0, 0);
controls.update();
scene.add(new THREE.HemisphereLight(0xffffff, 0x334455, 2.0));
const grid = new THREE.GridHelper(8, 16, 0x56606c, 0x2e353e);
scene.add(grid);
scene.add(new THREE.AxesHelper(0.5));

function resize() {
  const w = container.clientWidth, h = container.clientHeight;
  renderer.setSize(w, h);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
}
window.addEventListener('resize', resize);
resize();

const jointGeometry = new THREE.SphereGeometry(0.035, 12, 8);
const unitSphere = new THREE.SphereGeometry(1, 16, 12);
const colours = new Map();  // stream -> colour
function colourOf(stream) {
  if (FIXED_COLOURS[stream] !== undefined) return FIXED_COLOURS[stream];
  if (!colours.has(stream)) colours.set(stream, PALETTE[colours.size % PALETTE.length]);
  return colours.get(stream);
}

// --- layers (one per stream, plus sensors and gestures) --------------------
const layers = new Map();  // name -> { visible, row }
function layer(name, label, colour) {
  if (layers.has(name)) return layers.get(name);
  const row = document.createElement('label');
  row.className = 'row';
  const box = document.createElement('input');
  box.type = 'checkbox';
  box.checked = true;
  box.dataset.layer = name;
  const sw = document.createElement('span');
  sw.className = 'swatch';
  sw.style.background = '#' + colour.toString(16).padStart(6, '0');
  const text = document.createElement('span');
  text.textContent = label;
  const rate = document.createElement('span');
  rate.className = 'rate';
  row.append(box, sw, text, rate);
  document.getElementById('layers').appendChild(row);
  const l = { visible: true, rate };
  box.addEventListener('change', () => { l.visible = box.checked; dirty = true; });
  layers.set(name, l);
  return l;
}
layer('sensors', 'sensors and frustums', 0x9aa5b1);
layer('gestures', 'gestures', 0xff4040);
layer('uncertainty', 'uncertainty (95 % spheres)', 0xc0c0c0);
layer('robots', 'robots (safety state)', 0x9aa5b1);

// --- skeletons ------------------------------------------------------------
const skeletons = new Map();  // "stream/person" -> drawn objects
function makeSkeleton(stream, kind) {
  const colour = colourOf(stream);
  const group = new THREE.Group();
  const tracked = new THREE.MeshLambertMaterial({ color: colour });
  const inferred = new THREE.MeshLambertMaterial({ color: colour, transparent: true, opacity: 0.35, wireframe: true });
  const joints = [];
  for (let i = 0; i < 15; i++) {
    const m = new THREE.Mesh(jointGeometry, tracked);
    m.visible = false;
    group.add(m);
    joints.push(m);
  }
  // Each joint's 95 % region (fused skeletons that carry a covariance), translucent.
  const uncertainty = new THREE.Group();
  const shell = new THREE.MeshBasicMaterial({ color: colour, transparent: true, opacity: 0.15, depthWrite: false });
  const spheres = [];
  for (let i = 0; i < 15; i++) {
    const m = new THREE.Mesh(unitSphere, shell);
    m.visible = false;
    uncertainty.add(m);
    spheres.push(m);
  }
  group.add(uncertainty);
  const bonePositions = new Float32Array(BONES.length * 6);
  const boneGeometry = new THREE.BufferGeometry();
  boneGeometry.setAttribute('position', new THREE.BufferAttribute(bonePositions, 3));
  const bones = new THREE.LineSegments(boneGeometry, new THREE.LineBasicMaterial({
    color: colour, transparent: kind === 'truth', opacity: kind === 'truth' ? 0.6 : 1 }));
  group.add(bones);
  scene.add(group);
  return { group, joints, bones, bonePositions, tracked, inferred, stream, uncertainty, spheres };
}

function drawSkeleton(s) {
  const key = s.stream + '/' + s.person;
  let d = skeletons.get(key);
  if (!d) { d = makeSkeleton(s.stream, s.kind); skeletons.set(key, d); }
  d.seen = true;
  d.info = s;
  s.joints.forEach((j, i) => {
    const m = d.joints[i];
    m.visible = j[3] > 0;
    const u = d.spheres[i];
    u.visible = m.visible && j[4] > 0;
    if (u.visible) {
      u.position.set(j[0], j[1], j[2]);
      u.scale.setScalar(j[4]);
    }
    if (!m.visible) return;
    m.position.set(j[0], j[1], j[2]);
    m.material = j[3] === 2 ? d.tracked : d.inferred;
    m.scale.setScalar(j[3] === 2 ? 1 : 1.3);
  });
  BONES.forEach(([a, b], k) => {
    const ja = s.joints[a], jb = s.joints[b];
    const both = ja[3] > 0 && jb[3] > 0;
    for (let c = 0; c < 3; c++) {
      d.bonePositions[k * 6 + c] = both ? ja[c] : 0;
      d.bonePositions[k * 6 + 3 + c] = both ? jb[c] : 0;
    }
  });
  d.bones.geometry.attributes.position.needsUpdate = true;
  d.bones.geometry.computeBoundingSphere();
}

// --- sensors --------------------------------------------------------------
const sensors = new Map();  // id -> group
function drawSensor(s, frustum) {
  let g = sensors.get(s.id);
  if (!g) {
    const colour = colourOf(s.id);
    g = new THREE.Group();
    g.add(new THREE.Mesh(new THREE.BoxGeometry(0.28, 0.07, 0.07), new THREE.MeshLambertMaterial({ color: colour })));
    const tx = Math.tan(THREE.MathUtils.degToRad(frustum.fov_h_deg / 2));
    const ty = Math.tan(THREE.MathUtils.degToRad(frustum.fov_v_deg / 2));
    const f = frustum.far_m;
    // Sensor frame: z along the optical axis, y up, x to the sensor's left.
    const c = [[tx * f, ty * f, f], [-tx * f, ty * f, f], [-tx * f, -ty * f, f], [tx * f, -ty * f, f]];
    const p = [];
    for (const k of c) p.push(0, 0, 0, ...k);
    for (let i = 0; i < 4; i++) p.push(...c[i], ...c[(i + 1) % 4]);
    const geom = new THREE.BufferGeometry();
    geom.setAttribute('position', new THREE.Float32BufferAttribute(p, 3));
    g.add(new THREE.LineSegments(geom, new THREE.LineBasicMaterial({ color: colour, transparent: true, opacity: 0.45 })));
    scene.add(g);
    sensors.set(s.id, g);
  }
  g.position.set(...s.position);
  g.quaternion.set(s.rotation[1], s.rotation[2], s.rotation[3], s.rotation[0]);
  g.visible = layers.get('sensors').visible;
}

// --- gestures -------------------------------------------------------------
const gestureGroup = new THREE.Group();
scene.add(gestureGroup);
const rayMaterial = new THREE.LineBasicMaterial({ color: 0xff4040 });
const targetMaterial = new THREE.MeshBasicMaterial({ color: 0xff4040 });
const targetGeometry = new THREE.SphereGeometry(0.06, 16, 12);
function drawGestures(all) {
  // The newest event of each person and label (a held gesture repeats).
  const newest = new Map();
  for (const g of all) newest.set(`${g.person_id}/${g.label}`, g);
  const list = [...newest.values()];
  gestureGroup.clear();
  gestureGroup.visible = layers.get('gestures').visible;
  let rays = 0, targets = 0;
  for (const g of list) {
    if (!g.has_ray) continue;
    const o = g.ray_origin, dir = g.ray_direction;
    const end = g.has_target ? [g.target.x, g.target.y, g.target.z] : [o.x + 3 * dir.x, o.y + 3 * dir.y, o.z + 3 * dir.z];
    const geom = new THREE.BufferGeometry();
    geom.setAttribute('position', new THREE.Float32BufferAttribute([o.x, o.y, o.z, ...end], 3));
    gestureGroup.add(new THREE.Line(geom, rayMaterial));
    ++rays;
    if (g.has_target) {
      ++targets;
      const m = new THREE.Mesh(targetGeometry, targetMaterial);
      m.position.set(...end);
      gestureGroup.add(m);
    }
  }
  stats.drawnGestures = { rays, targets };
  const el = document.getElementById('gestures');
  if (list.length === 0) { el.textContent = 'none in the last seconds'; return; }
  el.replaceChildren(...list.map((g) => {
    const div = document.createElement('div');
    let t = `${g.label} by person ${g.person_id}`;
    if (g.arm) t += ` (${g.arm} arm)`;
    if (g.has_target) t += ` at ${g.target_name || 'target'}`;
    t += `, confidence ${Number(g.confidence).toFixed(2)}, ${(g.age_ms / 1000).toFixed(1)} s ago`;
    div.textContent = t;
    return div;
  }));
}

// --- robots: capsules coloured by the monitor's verdict -------------------------
const SAFETY_COLOURS = { RUN: 0x3fbf5f, REDUCED: 0xffb020, PROTECTIVE_STOP: 0xff3030 };
const robotGroup = new THREE.Group();
scene.add(robotGroup);
const robotMaterials = new Map();
function robotMaterial(state) {
  const key = state || 'none';
  if (!robotMaterials.has(key)) {
    robotMaterials.set(key, new THREE.MeshLambertMaterial({ color: SAFETY_COLOURS[state] ?? 0x9aa5b1, transparent: true, opacity: 0.8 }));
  }
  return robotMaterials.get(key);
}
const capsuleBody = new THREE.CylinderGeometry(1, 1, 1, 16, 1, true);
const capsuleEnd = new THREE.SphereGeometry(1, 16, 12);
const up = new THREE.Vector3(0, 1, 0);
function drawRobots(robots) {
  robotGroup.clear();
  robotGroup.visible = layers.get('robots').visible;
  const drawn = [];
  for (const r of robots) {
    const state = r.safety ? r.safety.state : null;
    const material = robotMaterial(state);
    let capsules = 0;
    for (const c of r.capsules) {
      const a = new THREE.Vector3(c[0], c[1], c[2]), b = new THREE.Vector3(c[3], c[4], c[5]), radius = c[6];
      const axis = new THREE.Vector3().subVectors(b, a);
      const length = axis.length();
      if (length > 1e-6) {
        const body = new THREE.Mesh(capsuleBody, material);
        body.scale.set(radius, length, radius);
        body.position.copy(a).addScaledVector(axis, 0.5);
        body.quaternion.setFromUnitVectors(up, axis.normalize());
        robotGroup.add(body);
      }
      for (const p of [a, b]) {
        const end = new THREE.Mesh(capsuleEnd, material);
        end.scale.setScalar(radius);
        end.position.copy(p);
        robotGroup.add(end);
      }
      ++capsules;
    }
    drawn.push({ id: r.id, capsules, state, colour: material.color.getHex() });
  }
  stats.drawnRobots = robotGroup.visible ? drawn : [];
  const el = document.getElementById('robots');
  if (robots.length === 0) { el.textContent = 'none'; return; }
  el.replaceChildren(...robots.map((r) => {
    const div = document.createElement('div');
    const s = r.safety;
    let t = `${r.id}: ${s ? s.state : 'no verdict yet'}, speed ${Math.round(100 * r.speed_scale)} %`;
    if (s && s.separation_m >= 0) t += `; person ${s.person_id} ${s.body_part} ${s.separation_m.toFixed(2)} m (S_p ${s.protective_m.toFixed(2)} m)`;
    div.textContent = t;
    if (s) div.title = s.reason;
    return div;
  }));
}

// --- panel: status, players -------------------------------------------------
function drawStatus(list) {
  const el = document.getElementById('status');
  if (list.length === 0) { el.textContent = 'no status yet'; return; }
  el.replaceChildren(...list.map((s) => {
    const div = document.createElement('div');
    div.className = s.state === 'STATE_OK' || s.state === 'OK' || s.state === 0 ? '' : 'bad';
    const state = String(s.state).replace('STATE_', '');
    div.textContent = `${s.component_name} (${s.host}): ${state}${s.message ? ' - ' + s.message : ''}`;
    return div;
  }));
}

let playersShown = '';
function drawPlayers(list) {
  const el = document.getElementById('players');
  const key = JSON.stringify(list.map((p) => p.player));
  if (list.length === 0) { if (playersShown !== '') el.textContent = 'no player of a recording'; playersShown = ''; return; }
  if (key !== playersShown) {
    playersShown = key;
    el.replaceChildren(...list.map((p) => {
      const div = document.createElement('div');
      div.dataset.player = p.player;
      div.innerHTML = `<div class="row"><b></b><span class="rate"></span></div>
        <div class="row"><input type="range" class="timeline" min="0" max="1" step="0.01" value="0" style="flex:1"></div>
        <div class="row"><button data-k="pause">Pause</button><button data-k="resume">Play</button>
        <button data-k="step">Step</button><select><option>0.25</option><option>0.5</option>
        <option selected>1</option><option>2</option><option>4</option></select>x</div>`;
      div.querySelector('b').textContent = p.player;
      for (const b of div.querySelectorAll('button')) {
        b.addEventListener('click', () => send({ cmd: 'play', kind: b.dataset.k, target: p.player, value: 1 }));
      }
      div.querySelector('select').addEventListener('change', (e) =>
        send({ cmd: 'play', kind: 'speed', target: p.player, value: Number(e.target.value) }));
      const timeline = div.querySelector('.timeline');
      timeline.addEventListener('input', () => { timeline.dataset.dragging = '1'; });
      timeline.addEventListener('change', () => {
        delete timeline.dataset.dragging;
        send({ cmd: 'play', kind: 'seek', target: p.player, value: Number(timeline.value) });
      });
      return div;
    }));
  }
  for (const p of list) {
    const div = el.querySelector(`[data-player="${CSS.escape(p.player)}"]`);
    if (!div) continue;
    const timeline = div.querySelector('.timeline');
    const where = p.position_s >= 0 && p.duration_s >= 0 ? `${p.position_s.toFixed(1)} / ${p.duration_s.toFixed(1)} s`
                                                          : `frame ${p.frames}${p.frame_count >= 0 ? ' of ' + p.frame_count : ''}`;
    timeline.style.display = p.duration_s > 0 ? '' : 'none';
    if (p.duration_s > 0 && !timeline.dataset.dragging) {
      timeline.max = p.duration_s;
      timeline.value = p.position_s;
    }
    div.querySelector('.rate').textContent =
      `${p.paused ? 'paused' : 'playing'} ${p.speed}x, ${where}${p.at_end ? ', at the end' : ''}${p.error ? ' (' + p.error + ')' : ''}`;
  }
}

// --- frames in, frames drawn --------------------------------------------------
let pending = null;  // newest frame not drawn yet (older ones are skipped)
let dirty = false;
function apply(frame) {
  stats.sensors = frame.sensors.length;
  for (const s of frame.sensors) drawSensor(s, frame.frustum);
  for (const d of skeletons.values()) d.seen = false;
  for (const s of frame.skeletons) {
    const l = layer(s.stream, `${s.stream} (${s.kind})`, colourOf(s.stream));
    drawSkeleton(s);
    skeletons.get(s.stream + '/' + s.person).group.visible = l.visible;
  }
  for (const [key, d] of skeletons) {
    if (!d.seen) { scene.remove(d.group); skeletons.delete(key); }
  }
  for (const [name, st] of Object.entries(frame.streams)) {
    const l = layer(name, `${name} (${st.kind})`, colourOf(name));
    l.rate.textContent = `${st.rate_hz.toFixed(1)} Hz${frame.unplaced.includes(name) ? ', no pose yet' : ''}`;
  }
  stats.streams = frame.streams;
  stats.gestures = frame.gestures;
  stats.players = frame.players;
  drawGestures(frame.gestures);
  drawRobots(frame.robots || []);
  drawStatus(frame.status);
  drawPlayers(frame.players);
  stats.lastSeq = frame.seq;
}

// What is on screen now, counted from the drawn objects themselves.
function count() {
  const list = [];
  let joints = 0;
  for (const d of skeletons.values()) {
    if (!d.group.visible) continue;
    const n = d.joints.filter((m) => m.visible).length;
    joints += n;
    const spheres = d.uncertainty.visible ? d.spheres.filter((m) => m.visible) : [];
    list.push({ stream: d.info.stream, kind: d.info.kind, person: d.info.person, frame: d.info.frame, joints: n,
                uncertainty: spheres.length,
                radius_95_max: spheres.reduce((r, m) => Math.max(r, m.scale.x), 0) });
  }
  stats.drawn = { skeletons: list.length, joints, list };
}

let drawnTimes = [];
function render(now) {
  requestAnimationFrame(render);
  if (pending && !stats.paused) {
    apply(pending);
    pending = null;
    dirty = true;
    stats.framesDrawn++;
    drawnTimes.push(now);
  }
  if (dirty) {
    for (const d of skeletons.values()) {
      d.group.visible = layers.get(d.info.stream)?.visible ?? true;
      d.uncertainty.visible = layers.get('uncertainty').visible;
    }
    for (const g of sensors.values()) g.visible = layers.get('sensors').visible;
    gestureGroup.visible = layers.get('gestures').visible;
    count();
    dirty = false;
  }
  while (drawnTimes.length && now - drawnTimes[0] > 2000) drawnTimes.shift();
  stats.fps = drawnTimes.length > 1 ? (1000 * (drawnTimes.length - 1)) / (drawnTimes[drawnTimes.length - 1] - drawnTimes[0]) : 0;
  document.getElementById('fps').textContent = `${stats.fps.toFixed(1)} drawn/s, seq ${stats.lastSeq}`;
  controls.update();
  renderer.render(scene, camera);
}
requestAnimationFrame(render);

document.getElementById('pause').addEventListener('click', (e) => {
  stats.paused = !stats.paused;
  e.target.textContent = stats.paused ? 'Resume' : 'Pause';
  document.getElementById('paused').textContent = stats.paused ? 'view frozen' : '';
});

// --- the WebSocket ------------------------------------------------------------
let ws = null;
function send(obj) { if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(obj)); }
window.skelgraphSend = (text) => { if (ws && ws.readyState === WebSocket.OPEN) ws.send(text); };
function connect() {
  const url = new URL('ws', window.location.href);
  url.protocol = url.protocol === 'https:' ? 'wss:' : 'ws:';
  ws = new WebSocket(url);
  const conn = document.getElementById('conn');
  ws.onopen = () => { stats.connected = true; conn.textContent = 'live'; conn.className = 'good'; };
  ws.onclose = () => {
    stats.connected = false;
    conn.textContent = 'reconnecting';
    conn.className = 'bad';
    setTimeout(connect, 1000);
  };
  ws.onmessage = (e) => {
    const m = JSON.parse(e.data);
    if (m.type === 'frame') { stats.framesReceived++; pending = m; }
    else if (m.type === 'error') stats.errors.push(m.message);
    else stats.replies.push(m);
  };
}
connect();
