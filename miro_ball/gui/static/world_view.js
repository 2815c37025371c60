// The world view: the simulator's scene (/miro_sim/scene as markers) drawn with three.js,
// each marker hung on a group per TF frame, so robots move as their transforms arrive.
// Coordinates stay ROS's (x forward, y left, z up; the camera's "up" is +z). The view is
// drawn only when something changed (a transform, a marker, the camera), so a still world
// costs the browser nothing; `continuous` draws every animation frame (the benchmark).
// The left button orbits, or drags an object or robot across its floor, or strokes MiRo,
// as the "hand" says; the page (app.js) does the talking to the server.
import * as THREE from './vendor/three/three.module.js';
import { OrbitControls } from './vendor/three/OrbitControls.js';
import { homeView } from './framing.js';

const WORLD = 'world';
// Unnamed static shapes carry their world-file table as namespace; everything else in the
// world frame is a named object, which the simulator's set_pose can move (a named static
// one it refuses to move: the page shows it back where the simulator says on release).
const STATIC_TABLES = new Set(['wall', 'ring', 'table', 'box', 'cylinder', 'sphere', 'ground',
                               'picture', 'sound']);
const TOUCH_LINKS = new Set(['head', 'body']);
const PLACE_PERIOD_MS = 40;  // 25 places a second while dragging (the server takes 30)
const HOLD_PERIOD_MS = 100;  // a held drag keeps re-placing: a robot stays under the pointer
const LABEL_ABOVE_M = 0.4;
const FOV_LENGTH_M = 1.0;

function unitGeometries() {
  const cylinder = new THREE.CylinderGeometry(0.5, 0.5, 1, 24);
  cylinder.rotateX(Math.PI / 2);  // three's cylinders stand along y, ROS's along z
  return {
    box: new THREE.BoxGeometry(1, 1, 1),
    sphere: new THREE.SphereGeometry(0.5, 24, 16),
    cylinder,
  };
}

function finite(list, n) {
  return Array.isArray(list) && list.length === n && list.every(Number.isFinite);
}

export class WorldView {
  // canvas: the <canvas>; labels: a <div> over it; hooks: {place(name, x, y),
  // sound(x, y), unsound(name), touch(part, u, v), untouch(), hint(text)}.
  constructor(canvas, labels, hooks) {
    this.canvas = canvas;
    this.labelBox = labels;
    this.hooks = hooks;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: false });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0xcfd8dc);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x606060, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.6);
    sun.position.set(-2, -3, 6);
    this.scene.add(sun);
    this.world = new THREE.Group();
    this.scene.add(this.world);
    this.frames = new Map([[WORLD, this.world]]);
    this.markers = new Map();  // id: {data, obj}
    this.geometries = unitGeometries();
    this.materials = new Map();
    this.textures = new Map();
    this.camera = new THREE.PerspectiveCamera(45, 16 / 9, 0.02, 200);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(0, -3, 2.5);
    this.raycaster = new THREE.Raycaster();
    // Ours before the orbit controls' own, so a press on an object is a drag, not an orbit.
    canvas.addEventListener('pointerdown', (e) => this.onDown(e), { capture: true });
    canvas.addEventListener('pointermove', (e) => this.onMove(e));
    for (const end of ['pointerup', 'pointercancel']) {
      canvas.addEventListener(end, (e) => this.onUp(e));
    }
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.maxPolarAngle = Math.PI * 0.495;  // never under the floor
    this.controls.addEventListener('change', () => { this.dirty = true; this.userMoved = true; });
    this.mode = 'move';
    this.follow = '';
    this.followAt = null;
    this.ownRobot = '';
    this.showFov = false;
    this.fovDeg = null;
    this.fovLines = new Map();  // robot: [lines of the left eye, of the right]
    this.labels = new Map();  // robot: <div>
    this.grab = null;
    this.stroke = null;
    this.active = true;
    this.dirty = true;
    this.continuous = false;
    this.userMoved = false;
    this.fitted = false;
    this.drawn = 0;  // frames drawn, for tests and the benchmark
    this.drawMs = [];
    new ResizeObserver(() => this.resize()).observe(canvas);
    this.resize();
    const loop = () => { requestAnimationFrame(loop); this.tick(); };
    requestAnimationFrame(loop);
  }

  // ---- incoming ---------------------------------------------------------------------------
  clear() {
    for (const id of [...this.markers.keys()]) this.remove(id);
    for (const [name, group] of this.frames) {
      if (name !== WORLD) group.visible = false;
    }
    this.fitted = false;
    this.dirty = true;
  }

  applyScene(message) {
    for (const id of message.removed || []) this.remove(id);
    for (const m of message.markers || []) {
      try {
        this.upsert(m);
      } catch (err) {
        console.warn('world view: marker ignored', m && m.id, err);
      }
    }
    this.updateRobots();
    if (!this.fitted && !this.userMoved) this.home();
    this.dirty = true;
  }

  applyTf(message) {
    for (const [child, t] of Object.entries(message.frames || {})) {
      if (child === WORLD || !t || typeof t.parent !== 'string'
          || !finite(t.p, 3) || !finite(t.q, 4)) continue;
      const group = this.frame(child);
      const parent = this.frame(t.parent);
      if (group.parent !== parent) {
        if (this.isAncestor(group, parent)) continue;  // a loop: keep the old tree
        parent.add(group);
      }
      group.position.fromArray(t.p);
      group.quaternion.fromArray(t.q);
      group.visible = true;
    }
    if (!this.fitted && !this.userMoved) this.home();  // the robots may come after the scene
    this.dirty = true;
  }

  setState(state) {
    const own = state.robot || '';
    const fov = Array.isArray(state.eye_fov_deg) && finite(state.eye_fov_deg, 2)
      ? state.eye_fov_deg : null;
    if (own !== this.ownRobot || String(fov) !== String(this.fovDeg)) {
      this.ownRobot = own;
      this.fovDeg = fov;
      this.updateFov();
      for (const [name, label] of this.labels) label.classList.toggle('mine', name === own);
      this.dirty = true;
    }
  }

  // ---- markers ----------------------------------------------------------------------------
  frame(name) {
    let group = this.frames.get(name);
    if (!group) {
      group = new THREE.Group();
      group.name = name;
      group.visible = false;  // until its transform arrives: nothing drawn at the origin
      this.world.add(group);
      this.frames.set(name, group);
    }
    return group;
  }

  isAncestor(node, of) {
    for (let n = of; n; n = n.parent) if (n === node) return true;
    return false;
  }

  material(rgba, kind) {
    const key = `${kind}:${rgba.join(',')}`;
    let material = this.materials.get(key);
    if (!material) {
      const [r, g, b, a] = rgba;
      material = new THREE.MeshLambertMaterial({ transparent: a < 1, opacity: a });
      material.color.setRGB(r, g, b, THREE.SRGBColorSpace);
      this.materials.set(key, material);
    }
    return material;
  }

  texture(url) {
    let texture = this.textures.get(url);
    if (!texture) {
      texture = new THREE.TextureLoader().load(url, () => { this.dirty = true; });
      texture.colorSpace = THREE.SRGBColorSpace;
      this.textures.set(url, texture);
    }
    return texture;
  }

  upsert(m) {
    if (typeof m.id !== 'string' || typeof m.frame !== 'string'
        || !finite(m.p, 3) || !finite(m.q, 4) || !finite(m.scale, 3)) {
      throw new Error('malformed marker');
    }
    const old = this.markers.get(m.id);
    const shape = (d) => `${d.kind}|${(d.points || []).length}|${d.texture || ''}`;
    let obj = old && shape(old.data) === shape(m) ? old.obj : null;
    if (!obj) {
      if (old) this.remove(m.id);
      obj = this.build(m);
    } else {
      this.restyle(obj, m);
    }
    const held = this.grab && this.grab.name === m.ns && m.frame === WORLD;
    if (!held || obj !== old?.obj) {  // what the hand holds stays under the pointer
      obj.position.fromArray(m.p);
      obj.quaternion.fromArray(m.q);
    }
    if (m.kind !== 'cube_list') {
      obj.scale.fromArray(m.kind === 'picture' ? m.scale.map((s) => (s > 0 ? s : 1)) : m.scale);
    }
    obj.visible = !(m.colour && m.colour[3] <= 0) || m.kind === 'picture';
    const frame = this.frame(m.frame);
    if (obj.parent !== frame) frame.add(obj);
    obj.userData.marker = m;
    this.markers.set(m.id, { data: m, obj });
  }

  build(m) {
    const colour = finite(m.colour, 4) ? m.colour : [0.7, 0.7, 0.7, 1];
    if (m.kind in this.geometries) {
      return new THREE.Mesh(this.geometries[m.kind], this.material(colour, 'solid'));
    }
    if (m.kind === 'cube_list') {
      const points = m.points || [];
      const mesh = new THREE.InstancedMesh(this.geometries.box,
        this.material([1, 1, 1, 1], 'solid'), Math.max(points.length, 1));
      this.restyle(mesh, m);
      return mesh;
    }
    if (m.kind === 'picture') {
      const points = (m.points || []).filter((pt) => finite(pt, 3));
      const uv = (m.uv || []).filter((c) => finite(c, 2));
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.Float32BufferAttribute(points.flat(), 3));
      if (uv.length === points.length) {
        geometry.setAttribute('uv', new THREE.Float32BufferAttribute(uv.flat(), 2));
      }
      if (points.length === 4) geometry.setIndex([0, 1, 2, 0, 2, 3]);  // corners only
      const material = new THREE.MeshBasicMaterial({ side: THREE.DoubleSide });
      if (typeof m.texture === 'string' && m.texture.startsWith('/texture/')) {
        material.map = this.texture(m.texture);
      } else {
        material.color.setRGB(...colour.slice(0, 3), THREE.SRGBColorSpace);
      }
      return new THREE.Mesh(geometry, material);
    }
    throw new Error(`unknown marker kind ${m.kind}`);
  }

  restyle(obj, m) {
    if (m.kind in this.geometries && finite(m.colour, 4)) {
      obj.material = this.material(m.colour, 'solid');
    } else if (m.kind === 'cube_list') {
      const matrix = new THREE.Matrix4();
      const colour = new THREE.Color();
      const scale = new THREE.Vector3().fromArray(m.scale);
      const none = new THREE.Quaternion();
      (m.points || []).forEach((pt, i) => {
        if (i >= obj.count || !finite(pt, 3)) return;
        obj.setMatrixAt(i, matrix.compose(new THREE.Vector3().fromArray(pt), none, scale));
        const c = (m.colours && finite(m.colours[i], 4)) ? m.colours[i] : m.colour;
        colour.setRGB(c[0], c[1], c[2], THREE.SRGBColorSpace);
        obj.setColorAt(i, colour);
      });
      obj.instanceMatrix.needsUpdate = true;
      if (obj.instanceColor) obj.instanceColor.needsUpdate = true;
    }
  }

  remove(id) {
    const entry = this.markers.get(id);
    if (!entry) return;
    entry.obj.removeFromParent();
    if (entry.data.kind === 'picture') {
      entry.obj.geometry.dispose();
      entry.obj.material.dispose();
    } else if (entry.data.kind === 'cube_list') {
      entry.obj.dispose();
    }
    this.markers.delete(id);
    this.dirty = true;
  }

  // A robot is a namespace whose markers hang on its own frames ('<robot>/<link>').
  robotOf(m) {
    return m.frame.startsWith(m.ns + '/') ? m.ns : null;
  }

  robotNames() {
    const names = new Set();
    for (const { data } of this.markers.values()) {
      const robot = this.robotOf(data);
      if (robot) names.add(robot);
    }
    return [...names].sort();
  }

  updateRobots() {
    const names = this.robotNames();
    if (String(names) === String(this.robotList)) return;
    this.robotList = names;
    for (const name of names) {
      if (!this.labels.has(name)) {
        const label = document.createElement('div');
        label.textContent = name;
        label.classList.toggle('mine', name === this.ownRobot);
        this.labelBox.appendChild(label);
        this.labels.set(name, label);
      }
    }
    for (const [name, label] of this.labels) {
      if (!names.includes(name)) { label.remove(); this.labels.delete(name); }
    }
    this.updateFov();
    if (this.onRobots) this.onRobots(names);
  }

  // ---- eyes' fields of view -----------------------------------------------------------------
  updateFov() {
    for (const lines of this.fovLines.values()) {
      lines.forEach((l) => { l.removeFromParent(); l.geometry.dispose(); l.material.dispose(); });
    }
    this.fovLines.clear();
    if (!this.showFov || !this.fovDeg || !this.ownRobot) return;
    const [h, v] = this.fovDeg.map((deg) => (deg * Math.PI) / 360);
    const x = FOV_LENGTH_M * Math.tan(h);
    const y = FOV_LENGTH_M * Math.tan(v);
    const z = FOV_LENGTH_M;
    // An optical frame looks along +z, x to the right, y down.
    const corners = [[-x, -y, z], [x, -y, z], [x, y, z], [-x, y, z]];
    const segments = [];
    corners.forEach((c, i) => segments.push(0, 0, 0, ...c, ...c, ...corners[(i + 1) % 4]));
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(segments, 3));
    const lines = ['caml', 'camr'].map((eye, i) => {
      const line = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({
        color: i === 0 ? 0xff00ff : 0x00b8d4 }));
      this.frame(`${this.ownRobot}/${eye}_optical`).add(line);
      return line;
    });
    this.fovLines.set(this.ownRobot, lines);
    this.dirty = true;
  }

  setShowFov(on) {
    this.showFov = on;
    this.updateFov();
    this.dirty = true;
  }

  // ---- camera -------------------------------------------------------------------------------
  // Everything that matters (framing.js): the robots, the objects and the walls, not the
  // ground. Fitted once every robot of the scene is placed by /tf.
  home() {
    this.scene.updateMatrixWorld();
    const boxes = [];
    const placed = new Set();
    for (const { data, obj } of this.markers.values()) {
      const robot = this.robotOf(data);
      if (robot ? !this.worldOf(`${robot}/body`) : data.frame !== WORLD || data.ns === 'ground') continue;
      if (robot) placed.add(robot);
      const box = new THREE.Box3().setFromObject(obj);
      if (!box.isEmpty()) boxes.push([box.min.toArray(), box.max.toArray()]);
    }
    const view = homeView(boxes, this.camera.fov, this.camera.aspect)
      || homeView([[[-1.3, -1.3, 0], [1.3, 1.3, 0.3]]], this.camera.fov, this.camera.aspect);
    this.fitted = boxes.length > 0 && this.robotNames().every((name) => placed.has(name));
    this.setView(view.position, view.target);
    this.userMoved = false;
  }

  setView(position, target) {
    this.camera.position.fromArray(position);
    this.controls.target.fromArray(target);
    this.controls.update();
    this.followAt = null;
    this.dirty = true;
  }

  setFollow(name) {
    this.follow = name;
    this.followAt = null;
    this.dirty = true;
  }

  worldOf(frameName) {
    const group = this.frames.get(frameName);
    if (!group || !group.visible) return null;
    group.updateWorldMatrix(true, false);
    return new THREE.Vector3().setFromMatrixPosition(group.matrixWorld);
  }

  // The camera keeps its offset from the followed robot: it moves as the robot moves.
  keepFollowing() {
    if (!this.follow) return;
    const at = this.worldOf(`${this.follow}/body`);
    if (!at) return;
    if (this.followAt === null) {
      const offset = this.camera.position.clone().sub(this.controls.target);
      this.controls.target.copy(at);
      this.camera.position.copy(at).add(offset);
    } else {
      const delta = at.clone().sub(this.followAt);
      this.controls.target.add(delta);
      this.camera.position.add(delta);
    }
    this.followAt = at;
    this.controls.update();
  }

  resize() {
    const w = this.canvas.clientWidth;
    const h = this.canvas.clientHeight;
    if (!w || !h) return;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.dirty = true;
  }

  // ---- drawing ------------------------------------------------------------------------------
  tick() {
    if (!this.active || !(this.dirty || this.continuous)) return;
    const start = performance.now();
    this.dirty = false;
    this.keepFollowing();
    this.renderer.render(this.scene, this.camera);
    this.placeLabels();
    this.drawn++;
    this.drawMs.push(performance.now() - start);
    if (this.drawMs.length > 300) this.drawMs.shift();
  }

  placeLabels() {
    const w = this.canvas.clientWidth;
    const h = this.canvas.clientHeight;
    for (const [name, label] of this.labels) {
      const at = this.worldOf(`${name}/body`);
      if (!at) { label.hidden = true; continue; }
      at.z += LABEL_ABOVE_M;
      at.project(this.camera);
      label.hidden = at.z > 1 || Math.abs(at.x) > 1 || Math.abs(at.y) > 1;
      label.style.left = `${((at.x + 1) / 2) * w}px`;
      label.style.top = `${((1 - at.y) / 2) * h}px`;
    }
  }

  // Page (client) pixel of a world point: for tests, which press where a user would.
  screenOf(point) {
    this.scene.updateMatrixWorld();
    const v = new THREE.Vector3().fromArray(point).project(this.camera);
    const rect = this.canvas.getBoundingClientRect();
    return { x: rect.left + ((v.x + 1) / 2) * rect.width,
             y: rect.top + ((1 - v.y) / 2) * rect.height };
  }

  // World position of a named object (its first marker) or of a robot (its body frame).
  positionOf(name) {
    const robot = this.worldOf(`${name}/body`);
    if (robot) return robot.toArray();
    for (const { data, obj } of this.markers.values()) {
      if (data.ns === name && data.frame === WORLD) {
        return obj.getWorldPosition(new THREE.Vector3()).toArray();
      }
    }
    return null;
  }

  // A point of a robot link's shapes, in the world: fractions of the box around them in the
  // link's frame (x forward, y left, z up; [0.5, 0.5, 0.5] is its centre, beyond 0..1 outside).
  linkPoint(robot, link, fractions = [0.5, 0.5, 0.5]) {
    const box = this.linkBox(robot, link);
    const group = this.frames.get(`${robot}/${link}`);
    if (!box || !group || !finite(fractions, 3)) return null;
    const size = box.getSize(new THREE.Vector3());
    const local = new THREE.Vector3(...fractions).multiply(size).add(box.min);
    group.updateWorldMatrix(true, false);
    return local.applyMatrix4(group.matrixWorld).toArray();
  }

  // What the hand would take at a page (client) pixel: [marker id, its link] or null.
  hitAt(x, y) {
    const hit = this.pick({ clientX: x, clientY: y });
    return hit ? [hit.m.id, hit.m.link || null] : null;
  }

  // ---- the hand -----------------------------------------------------------------------------
  rayFrom(e) {
    const rect = this.canvas.getBoundingClientRect();
    const ndc = new THREE.Vector2(((e.clientX - rect.left) / rect.width) * 2 - 1,
      -((e.clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    return this.raycaster.ray;
  }

  shown(obj) {
    for (let n = obj; n; n = n.parent) if (!n.visible) return false;
    return true;
  }

  // The nearest drawn marker under the pointer: {m, obj, point}.
  pick(e) {
    this.rayFrom(e);
    this.scene.updateMatrixWorld();
    const objects = [...this.markers.values()].map((entry) => entry.obj).filter((o) => this.shown(o));
    const hit = this.raycaster.intersectObjects(objects, false)[0];
    return hit ? { m: hit.object.userData.marker, obj: hit.object, point: hit.point } : null;
  }

  onDown(e) {
    if (e.button !== 0 || !e.isPrimary) return;
    const hit = this.pick(e);
    if (this.mode === 'sound') {  // a click on a sound stops it, anywhere else places one
      e.stopImmediatePropagation();
      if (hit && hit.m.ns === 'sound' && hit.m.text) {
        this.hooks.unsound(hit.m.text);
        return;
      }
      const floor = new THREE.Plane(new THREE.Vector3(0, 0, 1), 0);
      const at = this.rayFrom(e).intersectPlane(floor, new THREE.Vector3());
      if (at) this.hooks.sound(at.x, at.y);
      return;
    }
    if (!hit) return;
    const robot = this.robotOf(hit.m);
    if (this.mode === 'stroke') {
      if (!robot || !TOUCH_LINKS.has(hit.m.link)) return;
      if (robot !== this.ownRobot) {
        this.hooks.hint(`choose ${robot} as this page's robot to touch it`);
        return;
      }
      this.startHold(e);
      this.stroke = { robot, link: hit.m.link };
      this.strokeAt(hit);
      return;
    }
    const name = robot || (hit.m.frame === WORLD && !STATIC_TABLES.has(hit.m.ns) ? hit.m.ns : null);
    if (!name) return;
    // Dragged in the horizontal plane through the thing's centre, so the pointer keeps its
    // place on it: moving the pointer from one point's image to another's moves it by their
    // difference.
    const centre = robot ? this.worldOf(`${robot}/body`)
      : hit.obj.getWorldPosition(new THREE.Vector3());
    if (!centre) return;
    const plane = new THREE.Plane(new THREE.Vector3(0, 0, 1), -centre.z);
    const under = this.rayFrom(e).intersectPlane(plane, new THREE.Vector3());
    if (!under) return;
    this.startHold(e);
    // An object is shown under the pointer at once; a robot's links (frames of their own)
    // follow the simulator's word, 30 times a second.
    const parts = robot ? [] : [...this.markers.values()]
      .filter(({ data }) => data.ns === name && data.frame === WORLD)
      .map(({ obj }) => [obj, obj.position.clone()]);
    this.grab = { name, plane, centre, offset: centre.clone().sub(under), parts,
                  target: centre.clone(), sent: 0, changed: true };
    this.grab.timer = setInterval(() => this.sendPlace(false), PLACE_PERIOD_MS);
    this.sendPlace(true);
  }

  startHold(e) {
    e.stopImmediatePropagation();  // not an orbit
    this.controls.enabled = false;
    this.canvas.setPointerCapture(e.pointerId);
    this.pointer = e.pointerId;
  }

  onMove(e) {
    if (e.pointerId !== this.pointer) return;
    if (this.grab) {
      const under = this.rayFrom(e).intersectPlane(this.grab.plane, new THREE.Vector3());
      if (!under) return;  // above the horizon
      const target = under.add(this.grab.offset);
      const delta = target.clone().sub(this.grab.centre);
      // Shown there at once; the simulator's own word follows.
      for (const [obj, start] of this.grab.parts) obj.position.copy(start).add(delta);
      this.grab.target = target;
      this.grab.changed = true;
      this.dirty = true;
    } else if (this.stroke) {
      const hit = this.pick(e);
      if (hit && this.robotOf(hit.m) === this.stroke.robot && hit.m.link === this.stroke.link) {
        this.strokeAt(hit);
      } else {
        this.hooks.untouch();  // off the part: the hand is lifted
      }
    }
  }

  onUp(e) {
    if (e.pointerId !== this.pointer) return;
    this.pointer = null;
    this.controls.enabled = true;
    if (this.grab) {
      clearInterval(this.grab.timer);
      this.sendPlace(true);
      // Back to what the simulator last said; its next word shows where it really is.
      for (const [obj] of this.grab.parts) obj.position.fromArray(obj.userData.marker.p);
      this.grab = null;
      this.dirty = true;
    }
    if (this.stroke) {
      this.stroke = null;
      this.hooks.untouch();
    }
  }

  sendPlace(now) {
    const grab = this.grab;
    const t = performance.now();
    if (!now && !grab.changed && t - grab.sent < HOLD_PERIOD_MS) return;
    grab.changed = false;
    grab.sent = t;
    this.hooks.place(grab.name, grab.target.x, grab.target.y);
  }

  // The box around a link's shapes, in the link's frame.
  linkBox(robot, link) {
    const box = new THREE.Box3();
    for (const { data, obj } of this.markers.values()) {
      if (data.link !== link || this.robotOf(data) !== robot || !obj.geometry) continue;
      if (!obj.geometry.boundingBox) obj.geometry.computeBoundingBox();
      obj.updateMatrix();
      box.union(obj.geometry.boundingBox.clone().applyMatrix4(obj.matrix));
    }
    return box.isEmpty() ? null : box;
  }

  // u from the front (0) to the back (1), v from the left (0) to the right (1) of the link's
  // shapes, as the touch sensor's pads are laid out (the link's x forward, y left).
  strokeAt(hit) {
    const { robot, link } = this.stroke;
    const box = this.linkBox(robot, link);
    if (!box) return;
    const local = hit.obj.parent.worldToLocal(hit.point.clone());
    const clamp = (x) => Math.min(Math.max(x, 0), 1);
    const u = clamp((box.max.x - local.x) / Math.max(box.max.x - box.min.x, 1e-6));
    const v = clamp((box.max.y - local.y) / Math.max(box.max.y - box.min.y, 1e-6));
    this.hooks.touch(link, u, v);
  }
}
