// The MiRo GUI page: images, readouts and the world's scene in, commands out, over one
// WebSocket. The server sends the newest frame of each channel and waits for our 'ack'
// before the next, so frames never pile up here; it sends only what the page says it shows
// ('view'), so hidden panels cost nothing. Driving is a command refreshed every
// DRIVE_REFRESH_MS while a key or button is held; the server stops the robot when the
// refreshes stop (key up, page hidden or closed, connection lost). The 3D world view is
// world_view.js, loaded on its own so that a browser without WebGL still gets the rest.

const DRIVE_REFRESH_MS = 100;
const ANIMATION_MS = 40;  // cosmetic animations: 25 updates a second
const DEBUG_FRESH_MS = 1000;  // show the controller's annotated frame while this fresh
const FPS_FRAMES = 15;  // the MDK GUI averages its frame rate over 15 frames
const LOG_LENGTH = 5000;
const TOUCH_PERIOD_MS = 50;  // a stroke is a stream: the sensor holds each for 0.25 s
const HINT_MS = 4000;
const TONE_GAIN = 0.3;  // at volume 255: loud enough, never harsh
const $ = (id) => document.getElementById(id);

// What tests and the benchmark read: frames drawn per channel, and when; demo mode's overlays
// drawn, and on which frame.
const gui = window.miroGui = { frames: {}, drawn: [], state: null, config: null, connected: false,
                               world: null, tones: [], mics: null, audio: [], overlaid: [] };

let ws = null;
let channels = [];
const frameTimes = {};
const lastDebug = {};

// A number with so many decimals, without the '-' of a '-0.0'.
function fixed(value, decimals) {
  return value.toFixed(decimals).replace(/^-(0\.?0*)$/, '$1');
}

function send(message) {
  if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(message));
}

function connect() {
  ws = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => { gui.connected = true; worldShown = false; showConnection(); };
  ws.onclose = () => { gui.connected = false; showConnection(); setTimeout(connect, 1000); };
  ws.onmessage = (event) => {
    if (typeof event.data === 'string') onText(JSON.parse(event.data));
    else onFrame(event.data);
  };
}

function showConnection() {
  $('conn').textContent = gui.connected ? 'connected' : 'not connected, retrying';
  $('conn').className = gui.connected ? 'good' : 'bad';
}

function onText(message) {
  if (message.t === 'config') { setUp(message); sendView(); }
  else if (message.t === 'state') showState(message);
  else if (message.t === 'scene') { if (gui.world) gui.world.applyScene(message); }
  else if (message.t === 'tf') { if (gui.world) gui.world.applyTf(message); }
  else if (message.t === 'overlay') onOverlay(message);
  else if (message.t === 'tone') playTone(message);
  else if (message.t === 'mics') showMics(message);
  else if (message.t === 'audio') playAudio(message);
}

// ---- what this page shows -------------------------------------------------------------------
// The server subscribes to a robot's eyes, and to the scene, only while some page shows them.
let worldReady = false;  // the world view loaded and has WebGL
let worldShown = false;

function sendView() {
  const visible = !document.hidden;
  const wanted = [];
  if (visible && $('show_eyes').checked) {
    wanted.push('caml', 'camr');
    if ($('detections').checked) wanted.push('debug_caml', 'debug_camr');
  }
  if (visible && $('show_overhead').checked) wanted.push('overhead');
  const world = visible && worldReady && $('show_world').checked;
  if (world && !worldShown) gui.world.clear();  // the whole scene comes again
  worldShown = world;
  if (gui.world) gui.world.active = world;
  $('worldbox').hidden = !$('show_world').checked;
  $('eyesbox').hidden = $('eyesinfo').hidden = !$('show_eyes').checked;
  $('overheadbox').hidden = !$('show_overhead').checked;
  send({ t: 'view', channels: wanted.filter((c) => channels.includes(c)), world });
}

function hint(text) {
  $('world_hint').textContent = text;
  clearTimeout(hint.timer);
  hint.timer = setTimeout(() => { $('world_hint').textContent = ''; }, HINT_MS);
}

async function startWorld() {
  for (const id of ['show_world', 'show_eyes', 'show_overhead', 'detections']) {
    $(id).addEventListener('change', sendView);
  }
  document.addEventListener('visibilitychange', sendView);
  try {
    const { WorldView } = await import('./world_view.js');
    gui.world = new WorldView($('world-view'), $('world-labels'), {
      place: (name, x, y) => send({ t: 'place', name, x: round3(x), y: round3(y) }),
      sound: (x, y) => send({ t: 'sound', x: round3(x), y: round3(y), kind: $('sound_kind').value }),
      unsound: (name) => send({ t: 'unsound', name }),
      touch: touchAt, untouch, hint });
  } catch (err) {
    $('world_note').textContent = `This browser cannot draw the world view (${err.message}): `
      + 'the overhead image shows the world instead.';
    $('world_note').hidden = false;
    $('worldstage').hidden = $('worldtools').hidden = true;
    $('show_overhead').checked = true;
    sendView();
    return;
  }
  const world = gui.world;
  world.onRobots = (names) => {
    const follow = $('world_follow');
    const chosen = follow.value;
    follow.replaceChildren(new Option('nobody', ''), ...names.map((n) => new Option(n, n)));
    follow.value = names.includes(chosen) ? chosen : '';
  };
  $('world_mode').addEventListener('change', () => { world.mode = $('world_mode').value; });
  $('world_follow').addEventListener('change', () => world.setFollow($('world_follow').value));
  $('world_fov').addEventListener('change', () => world.setShowFov($('world_fov').checked));
  $('world_home').addEventListener('click', () => world.home());
  worldReady = true;
  sendView();
}

function round3(x) {
  return Math.round(x * 1000) / 1000;
}

// ---- touch: strokes from the world view or the body map ---------------------------------------
const stroke = { part: null, u: 0, v: 0, timer: null };

function touchAt(part, u, v) {
  Object.assign(stroke, { part, u: round3(u), v: round3(v) });
  if (stroke.timer === null) {
    sendTouch();
    stroke.timer = setInterval(sendTouch, TOUCH_PERIOD_MS);
  }
}

function sendTouch() {
  if (stroke.part) send({ t: 'touch', part: stroke.part, u: stroke.u, v: stroke.v });
}

function untouch() {
  stroke.part = null;
  clearInterval(stroke.timer);
  stroke.timer = null;
}

// MiRo from above, facing up: each part's pads in columns across (left to right) and rows
// along (front at the top), as miro/touch.py numbers them (bit = across * along + along).
const BODY_MAP = { head: [45, 8, 60, 72], body: [30, 92, 90, 130] };  // x, y, w, h
let touchGrid = { rows: 2, columns: 7 };

function drawBodyMap() {
  const canvas = $('bodymap');
  const ctx = canvas.getContext('2d');
  const r = (gui.state && gui.state.readouts) || {};
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  const { rows, columns } = touchGrid;
  for (const [part, [x, y, w, h]] of Object.entries(BODY_MAP)) {
    const mask = r[`touch_${part}`] || 0;
    const pw = w / rows;
    const ph = h / columns;
    for (let across = 0; across < rows; across++) {
      for (let along = 0; along < columns; along++) {
        const lit = (mask >> (across * columns + along)) & 1;
        ctx.fillStyle = lit ? '#ef6c00' : '#e3e3e3';
        ctx.fillRect(x + across * pw + 1, y + along * ph + 1, pw - 2, ph - 2);
      }
    }
    ctx.strokeStyle = '#2d3b45';
    ctx.strokeRect(x + 0.5, y + 0.5, w - 1, h - 1);
    ctx.fillStyle = '#2d3b45';
    ctx.font = '11px system-ui, sans-serif';
    ctx.fillText(part, x + w + 3 > canvas.width - 24 ? 2 : x + w + 3, y + 12);
  }
}

function setUpBodyMap() {
  const canvas = $('bodymap');
  const at = (e) => {
    const rect = canvas.getBoundingClientRect();
    const px = ((e.clientX - rect.left) * canvas.width) / rect.width;
    const py = ((e.clientY - rect.top) * canvas.height) / rect.height;
    for (const [part, [x, y, w, h]] of Object.entries(BODY_MAP)) {
      if (px >= x && px <= x + w && py >= y && py <= y + h) {
        return [part, (py - y) / h, (px - x) / w];
      }
    }
    return null;
  };
  canvas.addEventListener('pointerdown', (e) => {
    const where = at(e);
    if (!where) return;
    canvas.setPointerCapture(e.pointerId);
    touchAt(...where);
  });
  canvas.addEventListener('pointermove', (e) => {
    if (!canvas.hasPointerCapture(e.pointerId)) return;
    const where = at(e);
    if (where) touchAt(...where);
    else untouch();
  });
  for (const end of ['pointerup', 'pointercancel', 'lostpointercapture']) {
    canvas.addEventListener(end, untouch);
  }
  drawBodyMap();
}

// ---- sound: MiRo's tones, when the user has allowed them --------------------------------------
let audio = null;
let soundOn = false;

function setUpSound() {
  $('sound').addEventListener('click', () => {
    soundOn = !soundOn;
    if (soundOn && !audio) audio = new AudioContext();  // made in a click, as browsers ask
    if (audio && soundOn) audio.resume();
    $('sound').textContent = soundOn ? 'sound on' : 'sound off';
    $('sound').classList.toggle('on', soundOn);
  });
}

function playTone(message) {
  const { hz, volume, ticks } = message;
  if (![hz, volume, ticks].every(Number.isFinite) || !gui.config) return;
  gui.tones.push({ hz, volume, ticks, played: soundOn });
  if (gui.tones.length > 100) gui.tones.shift();
  if (!soundOn || !audio || hz <= 0 || volume <= 0 || ticks <= 0) return;
  const start = audio.currentTime;
  const seconds = Math.min(ticks, 255) * gui.config.tick_s;
  const osc = audio.createOscillator();
  const gain = audio.createGain();
  osc.frequency.value = Math.min(Math.max(hz, 20), 20000);
  gain.gain.setValueAtTime(TONE_GAIN * Math.min(volume, 255) / 255, start);
  gain.gain.linearRampToValueAtTime(0, start + seconds);  // no click at the end
  osc.connect(gain).connect(audio.destination);
  osc.start(start);
  osc.stop(start + seconds + 0.02);
}

// ---- hearing: the microphones' levels and spectrogram, what MiRo hears and says ----------
const LEVEL_FLOOR_DB = -90;
let audioAt = 0;  // when the next piece of sound starts playing (AudioContext time)

function setUpHearing(config) {
  $('mic').replaceChildren(...config.mics.map((name, i) => new Option(name, i)));
  $('sound_kind').replaceChildren(...config.sound_kinds.map((kind) => new Option(kind, kind)));
  $('miclevels').replaceChildren(...config.mics.map((name) => {
    const row = document.createElement('div');
    row.innerHTML = `<span>${name}</span><meter min="${LEVEL_FLOOR_DB}" max="0"></meter><output></output>`;
    return row;
  }));
  const tell = () => send({ t: 'hear', mic: Number($('mic').value), listen: $('listen').checked,
                            shown: $('hearing').open });
  $('mic').addEventListener('change', tell);
  $('listen').addEventListener('change', tell);
  $('hearing').addEventListener('toggle', tell);  // the microphones are read only while open
}

function showMics(message) {
  const { levels, spectrum } = message;
  if (!Array.isArray(levels) || !Array.isArray(spectrum)) return;
  gui.mics = message;
  $('miclevels').querySelectorAll('div').forEach((row, i) => {
    row.querySelector('meter').value = levels[i];
    row.querySelector('output').textContent = `${fixed(levels[i], 0)} dB`;
  });
  // The spectrogram scrolls left a column a message; loud is bright.
  const canvas = $('spectrogram');
  const ctx = canvas.getContext('2d');
  ctx.drawImage(canvas, -2, 0);
  const h = canvas.height / spectrum.length;
  spectrum.forEach((db, k) => {
    const light = Math.round(100 * Math.min(Math.max((db - LEVEL_FLOOR_DB) / -LEVEL_FLOOR_DB, 0), 1));
    ctx.fillStyle = `hsl(${240 - 2.4 * light}, 90%, ${light * 0.6}%)`;
    ctx.fillRect(canvas.width - 2, canvas.height - (k + 1) * h, 2, Math.ceil(h));
  });
}

// Sound from the server, int16 little-endian in base64, played back to back.
function playAudio(message) {
  const { rate, source, data } = message;
  if (!Number.isFinite(rate) || rate < 3000 || rate > 48000 || typeof data !== 'string') return;
  const bytes = Uint8Array.from(atob(data), (c) => c.charCodeAt(0));
  const samples = new Int16Array(bytes.buffer, 0, bytes.length >> 1);
  gui.audio.push({ source, rate, samples: samples.length, played: soundOn });
  if (gui.audio.length > 100) gui.audio.shift();
  if (!soundOn || !audio || !samples.length) return;
  const buffer = audio.createBuffer(1, samples.length, rate);
  const channel = buffer.getChannelData(0);
  for (let i = 0; i < samples.length; i++) channel[i] = samples[i] / 32768;
  const node = audio.createBufferSource();
  node.buffer = buffer;
  node.connect(audio.destination);
  // Late pieces start now; a queue of more than half a second is dropped to catch up.
  if (audioAt < audio.currentTime || audioAt > audio.currentTime + 0.5) audioAt = audio.currentTime + 0.05;
  node.start(audioAt);
  audioAt += buffer.duration;
}

// ---- demo mode: what the animal does, feels and attends to ---------------------------------
let demoActions = [];

function setUpDemo(config) {
  demoActions = config.actions || [];
  $('demo').addEventListener('toggle', () => send({ t: 'demo', shown: $('demo').open }));
  $('demo_start').addEventListener('click', () => send({ t: 'demo_run', run: true }));
  $('demo_stop').addEventListener('click', () => send({ t: 'demo_run', run: false }));
}

function showDemo(demo, state) {
  const running = (state.demo_running || []).includes(state.robot);
  $('demo_running').textContent = running ? `(runs for ${state.robot})` : '';
  gui.demo = demo || null;
  if (!$('demo').open || !demo) return;
  $('demo_action').textContent = demo.action || '-';
  if (Array.isArray(demo.priorities)) drawPriorities(demo.priorities, demo.action);
  if (demo.state) drawAffect(demo.state);
}

function drawPriorities(values, selected) {
  const canvas = $('demo_priorities');
  const ctx = canvas.getContext('2d');
  const row = canvas.height / Math.max(1, demoActions.length);
  const left = 70;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  ctx.font = '12px system-ui, sans-serif';
  ctx.textBaseline = 'middle';
  demoActions.forEach((name, i) => {
    const value = Math.min(Math.max(Number(values[i]) || 0, 0), 1);
    const y = i * row;
    ctx.fillStyle = '#333';
    ctx.fillText(name, 4, y + row / 2);
    ctx.strokeStyle = '#4a8bbf';
    ctx.strokeRect(left + 0.5, y + 3.5, canvas.width - left - 8, row - 7);
    ctx.fillStyle = name === selected ? '#2e7d32' : '#9ec3e0';
    ctx.fillRect(left + 1, y + 4, (canvas.width - left - 9) * value, row - 8);
  });
}

function drawAffect({ emotion, mood, sleep }) {
  const canvas = $('demo_affect');
  const ctx = canvas.getContext('2d');
  const w = canvas.width, h = canvas.height;
  const at = ([valence, arousal]) => [(valence + 1) / 2 * w, (1 - arousal) / 2 * h];
  ctx.clearRect(0, 0, w, h);
  ctx.strokeStyle = '#bbb';
  ctx.beginPath(); ctx.moveTo(w / 2, 0); ctx.lineTo(w / 2, h); ctx.moveTo(0, h / 2); ctx.lineTo(w, h / 2);
  ctx.stroke();
  ctx.fillStyle = '#777';
  ctx.font = '10px system-ui, sans-serif';
  ctx.fillText('happy', w - 32, h / 2 - 3); ctx.fillText('sad', 2, h / 2 - 3);
  ctx.fillText('alert', w / 2 + 3, 10); ctx.fillText('calm', w / 2 + 3, h - 3);
  const [mx, my] = at(mood);
  ctx.strokeStyle = '#6a1b9a'; ctx.lineWidth = 2;
  ctx.beginPath(); ctx.arc(mx, my, 8, 0, 2 * Math.PI); ctx.stroke();
  const [ex, ey] = at(emotion);
  ctx.fillStyle = '#c62828';
  ctx.beginPath(); ctx.arc(ex, ey, 5, 0, 2 * Math.PI); ctx.fill();
  ctx.lineWidth = 1;
  const [wake, pressure] = sleep;
  $('demo_wake').textContent = fixed(wake, 2);
  $('demo_pressure').textContent = fixed(pressure, 2);
  $('demo_wake_bar').firstChild.style.width = `${100 * wake}%`;
  $('demo_pressure_bar').firstChild.style.width = `${100 * pressure}%`;
}

// Demo mode's overlay of each channel, as the server paired it with one of the channel's
// frames (gui/pairing.py): drawn on that frame only.
const overlays = {};

function onOverlay(message) {
  const name = channels[message.ch];
  if (!name) return;
  overlays[name] = message;
  const target = name.replace(/^debug_/, '');
  const picture = shown[target];
  if (picture && picture.name === name && picture.stamp === message.frame) paint(target, picture);
}

// The attention map as this eye sees it, in red, and what the detectors found, labelled: the
// overlay that goes with the frame of `stamp` on channel `name`, if the page has it.
function demoOverlay(ctx, name, stamp, w, h) {
  const overlay = overlays[name];
  if (!overlay || overlay.frame !== stamp || !$('demo').open || !$('demo_overlay').checked) return;
  gui.overlaid.push({ ch: name, frame: stamp, stamp: overlay.stamp });
  if (gui.overlaid.length > LOG_LENGTH) gui.overlaid.splice(0, gui.overlaid.length - LOG_LENGTH);
  const view = overlay.view;
  if (view && view.w > 0 && view.h > 0 && typeof view.data === 'string') {
    const bytes = Uint8Array.from(atob(view.data), (c) => c.charCodeAt(0));
    if (bytes.length === view.w * view.h) {
      const small = new OffscreenCanvas(view.w, view.h);
      const picture = small.getContext('2d').createImageData(view.w, view.h);
      bytes.forEach((v, i) => picture.data.set([255, 40, 0, Math.round(0.6 * v)], 4 * i));
      small.getContext('2d').putImageData(picture, 0, 0);
      ctx.imageSmoothingEnabled = true;
      ctx.drawImage(small, 0, 0, w, h);
      gui.demoOverlays = (gui.demoOverlays || 0) + 1;
    }
  }
  ctx.lineWidth = Math.max(1, w / 320);
  ctx.font = `${Math.round(w / 40)}px system-ui, sans-serif`;
  for (const thing of Array.isArray(overlay.objects) ? overlay.objects : []) {
    const x = thing.x * w, y = thing.y * h;
    ctx.strokeStyle = ctx.fillStyle = thing.kind === 'ball' ? '#00e5ff' : thing.kind === 'face' ? '#ffeb3b' : '#76ff03';
    ctx.beginPath();
    if (thing.kind === 'ball') ctx.arc(x, y, thing.r * w, 0, 2 * Math.PI);
    else if (thing.kind === 'face') ctx.rect(x, y, thing.w * w, thing.h * h);
    else ctx.rect(x - 6, y - 6, 12, 12);
    ctx.stroke();
    ctx.fillText(thing.kind, x + 4, y - 4);
  }
}

// ---- images --------------------------------------------------------------------------------
function onFrame(buffer) {
  const view = new DataView(buffer);
  const ch = view.getUint8(0);
  const stamp = view.getFloat64(1, true);
  const blob = new Blob([new Uint8Array(buffer, 9)], { type: 'image/jpeg' });
  createImageBitmap(blob)
    .then((bitmap) => { if (!draw(channels[ch], stamp, bitmap)) bitmap.close(); })
    .catch(() => {})  // a corrupt JPEG: skip it, the next one comes
    .finally(() => send({ t: 'ack', ch }));
}

// The picture each canvas shows ({name, stamp, bitmap}), kept to be drawn again when the
// overlay of its frame comes after it.
const shown = {};

// Draw a frame of channel `name`; true if the page keeps its bitmap (shown[target]).
function draw(name, stamp, bitmap) {
  const now = performance.now();
  let target = name;
  if (name.startsWith('debug_')) {
    target = name.slice(6);
    lastDebug[target] = now;
    if (!$('detections').checked) return false;
  } else if (name !== 'overhead' && $('detections').checked
             && now - (lastDebug[name] || -1e9) < DEBUG_FRESH_MS) {
    return false;  // this eye is shown with the controller's detections drawn
  }
  if (!$(target)) return false;
  if (shown[target]) shown[target].bitmap.close();
  shown[target] = { name, stamp, bitmap };
  paint(target, shown[target]);
  gui.frames[name] = (gui.frames[name] || 0) + 1;
  gui.drawn.push({ ch: name, stamp, at: performance.timeOrigin + now });
  if (gui.drawn.length > LOG_LENGTH) gui.drawn.splice(0, gui.drawn.length - LOG_LENGTH);
  const times = frameTimes[target] = frameTimes[target] || [];
  times.push(now);
  if (times.length > FPS_FRAMES) times.shift();
  return true;
}

function paint(target, { name, stamp, bitmap }) {
  const canvas = $(target);
  if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {
    canvas.width = bitmap.width;
    canvas.height = bitmap.height;
  }
  const ctx = canvas.getContext('2d');
  ctx.drawImage(bitmap, 0, 0);
  if (target !== 'overhead') crossHairs(ctx, bitmap.width, bitmap.height, target === 'caml' ? 0.75 : 0.25);
  if (target === 'caml' || target === 'camr') demoOverlay(ctx, name, stamp, bitmap.width, bitmap.height);
}

// The MDK GUI's magenta centre cross and the "dead ahead" tick of each eye.
function crossHairs(ctx, w, h, aheadX) {
  ctx.strokeStyle = '#ff00ff';
  ctx.lineWidth = Math.max(1, w / 320);
  ctx.beginPath();
  ctx.moveTo(w / 2, 0); ctx.lineTo(w / 2, h);
  ctx.moveTo(0, h / 2); ctx.lineTo(w, h / 2);
  ctx.moveTo(aheadX * w, 0.45 * h); ctx.lineTo(aheadX * w, 0.55 * h);
  ctx.stroke();
}

function fps(name) {
  const t = frameTimes[name];
  if (!t || t.length < 2 || performance.now() - t[t.length - 1] > 2000) return '-';
  return ((t.length - 1) * 1000 / (t[t.length - 1] - t[0])).toFixed(1);
}

// ---- readouts ------------------------------------------------------------------------------
// [label, value from the readouts, bar from, bar to, decimals, unit]
const READOUTS = [
  ['battery', (r) => r.battery, 0, 6, 2, 'V'],
  ['sonar', (r) => r.sonar_text, 0, 1, null, '', (r) => r.sonar],
  ['cliff L', (r) => r.cliff && r.cliff[0], 0, 15, 0, ''],
  ['cliff R', (r) => r.cliff && r.cliff[1], 0, 15, 0, ''],
  ...['FL', 'FR', 'RL', 'RR'].map((n, i) => [`light ${n}`, (r) => r.light && r.light[i], 0, 100, 0, '']),
  ['touch head', (r) => r.touch_head, 0, 16383, 0, ''],
  ['touch body', (r) => r.touch_body, 0, 16383, 0, ''],
  ...['body', 'head'].flatMap((part) => ['x', 'y', 'z', '|a|'].map((axis, i) =>
    [`accel ${part} ${axis}`, (r) => r[`accel_${part}`] && r[`accel_${part}`][i], i === 3 ? 0 : -100, 100, 0, ''])),
  ['wheel L (opto)', (r) => r.wheel_opto && r.wheel_opto[0], -400, 400, 0, 'mm/s'],
  ['wheel R (opto)', (r) => r.wheel_opto && r.wheel_opto[1], -400, 400, 0, 'mm/s'],
  ['wheel L (cmd)', (r) => r.wheel_cmd && r.wheel_cmd[0], -400, 400, 0, 'mm/s'],
  ['wheel R (cmd)', (r) => r.wheel_cmd && r.wheel_cmd[1], -400, 400, 0, 'mm/s'],
  ['odom linear', (r) => r.odom && r.odom[0], -0.4, 0.4, 2, 'm/s'],
  ['odom angular', (r) => r.odom && r.odom[1], -5, 5, 2, 'rad/s'],
  ['pose x', (r) => r.pose && r.pose[0], -2, 2, 2, 'm'],
  ['pose y', (r) => r.pose && r.pose[1], -2, 2, 2, 'm'],
  ['pose yaw', (r) => r.pose && r.pose[2] * 180 / Math.PI, -180, 180, 0, 'deg'],
  ['head lift', (r) => r.head && r.head[0], 8, 60, 1, 'deg'],
  ['head yaw', (r) => r.head && r.head[1], -55, 55, 1, 'deg'],
  ['head pitch', (r) => r.head && r.head[2], -22, 8, 1, 'deg'],
];
const readoutCells = [];

function buildReadouts() {
  for (const [label] of READOUTS) {
    const row = $('readtable').insertRow();
    row.insertCell().textContent = label;
    row.cells[0].className = 'label';
    const value = row.insertCell();
    value.className = 'value';
    const bar = document.createElement('div');
    bar.className = 'bar';
    const fill = document.createElement('div');
    bar.appendChild(fill);
    row.insertCell().appendChild(bar);
    readoutCells.push([value, fill]);
  }
}

function showReadouts(readouts) {
  READOUTS.forEach(([, get, lo, hi, decimals, unit, barValue], i) => {
    const [cell, fill] = readoutCells[i];
    const v = get(readouts);
    const number = barValue ? barValue(readouts) : v;
    cell.textContent = v === undefined || v === null ? '-'
      : decimals === null ? v : `${fixed(v, decimals)}${unit ? ' ' + unit : ''}`;
    // A bar from zero (or the low end when zero is off the scale) to the value.
    const clamp = (x) => Math.min(Math.max(x, lo), hi);
    const zero = clamp(0);
    const end = typeof number === 'number' ? clamp(number) : zero;
    fill.style.left = `${(100 * (Math.min(zero, end) - lo)) / (hi - lo)}%`;
    fill.style.width = `${(100 * Math.abs(end - zero)) / (hi - lo)}%`;
  });
}

function showState(state) {
  const r = state.readouts || {};
  const touched = gui.state && gui.state.readouts
    && (gui.state.readouts.touch_head !== r.touch_head || gui.state.readouts.touch_body !== r.touch_body);
  gui.state = state;
  showReadouts(r);
  if (touched) drawBodyMap();
  if (gui.world) gui.world.setState(state);
  const picker = $('robot');
  const names = state.robots.includes(state.robot) ? state.robots : [state.robot, ...state.robots];
  if (picker.options.length !== names.length || names.some((n, i) => picker.options[i].value !== n)) {
    picker.replaceChildren(...names.map((n) => new Option(n, n)));
  }
  picker.value = state.robot;
  picker.disabled = state.fixed || names.length < 2;
  $('stale').textContent = state.age === null ? `no data from ${state.robot} yet`
    : state.age > 1 ? `no data from ${state.robot} for ${state.age.toFixed(0)} s` : '';
  $('stale').className = $('stale').textContent ? 'bad' : '';
  const sim = state.sim;
  $('sim').hidden = !sim.present;
  $('simtime').textContent = sim.time === null ? '-' : sim.time.toFixed(2);
  $('rtf').textContent = sim.rtf === null ? '-' : sim.rtf.toFixed(2);
  $('pause').textContent = sim.paused ? 'resume' : 'pause';
  showRtfSet(state.rtf_set !== undefined ? state.rtf_set : sim.rtf_set);
  $('status').textContent = state.status;
  showDemo(r.demo, state);
  $('fps').textContent = `${fps('caml')} / ${fps('camr')}`;
}

// ---- driving -------------------------------------------------------------------------------
const KEYS = { ArrowUp: 'f', KeyW: 'f', ArrowDown: 'b', KeyS: 'b',
               ArrowLeft: 'l', KeyA: 'l', ArrowRight: 'r', KeyD: 'r' };
const held = new Set();  // 'key:f', 'pad:l', ...
let driving = false;

function heldDir(dir) {
  for (const h of held) if (h.endsWith(':' + dir)) return 1;
  return 0;
}

function updateDrive() {
  const forward = heldDir('f') - heldDir('b');
  const turn = heldDir('l') - heldDir('r');
  if (forward === 0 && turn === 0) {
    if (driving) send({ t: 'stop' });
    driving = false;
    return;
  }
  driving = true;
  send({ t: 'drive', linear: forward * Number($('linear').value),
         angular: turn * Number($('angular').value) });
}

function releaseAll() {
  held.clear();
  updateDrive();
  send({ t: 'stop' });
}

function typing(target) {
  return target instanceof HTMLInputElement && ['text', 'number'].includes(target.type);
}

function setUpDriving() {
  window.addEventListener('keydown', (e) => {
    const dir = KEYS[e.code];
    if (!dir || typing(e.target) || e.ctrlKey || e.metaKey || e.altKey) return;
    e.preventDefault();
    if (e.repeat) return;
    held.add('key:' + dir);
    updateDrive();
  });
  window.addEventListener('keyup', (e) => {
    const dir = KEYS[e.code];
    if (!dir) return;
    held.delete('key:' + dir);
    updateDrive();
  });
  for (const button of document.querySelectorAll('#pad [data-dir]')) {
    const token = 'pad:' + button.dataset.dir;
    button.addEventListener('pointerdown', (e) => {
      button.setPointerCapture(e.pointerId);
      held.add(token);
      updateDrive();
    });
    for (const end of ['pointerup', 'pointercancel', 'lostpointercapture']) {
      button.addEventListener(end, () => { held.delete(token); updateDrive(); });
    }
  }
  $('stop').addEventListener('click', releaseAll);
  // Keys released while the page had no focus never reach us: stop on every way out.
  window.addEventListener('blur', releaseAll);
  window.addEventListener('pagehide', releaseAll);
  document.addEventListener('visibilitychange', () => { if (document.hidden) releaseAll(); });
  setInterval(() => { if (driving) updateDrive(); }, DRIVE_REFRESH_MS);
}

// ---- head, cosmetic, LEDs, tone, flags ----------------------------------------------------
function slider(parent, id, label, lo, hi, step, value, onInput) {
  const wrap = document.createElement('label');
  wrap.textContent = label + ' ';
  const input = document.createElement('input');
  Object.assign(input, { type: 'range', id, min: lo, max: hi, step, value });
  const out = document.createElement('output');
  out.textContent = Number(value).toFixed(step < 1 ? 2 : 0);
  const measured = document.createElement('span');
  measured.className = 'measured';
  measured.id = id + '_measured';
  input.addEventListener('input', () => { out.textContent = Number(input.value).toFixed(step < 1 ? 2 : 0); onInput(); });
  wrap.append(input, ' ', out, ' ', measured);
  parent.appendChild(wrap);
  parent.appendChild(document.createElement('br'));
  return input;
}

// A range input of the page's own (not made by slider()) shows its value beside it, in its
// <output id="<id>_out">, now and as it moves (as slider()'s: two decimals for a fine step).
function showValue(id) {
  const decimals = Number($(id).step || 1) < 1 ? 2 : 0;
  const show = () => { $(id + '_out').textContent = Number($(id).value).toFixed(decimals); };
  show();
  $(id).addEventListener('input', show);
}

const COSMETIC = ['tail droop', 'tail wag', 'eyelid L', 'eyelid R', 'ear L', 'ear R'];
let cosmeticInputs = [];
let animation = null;

function sendHead() {
  send({ t: 'head', lift: Number($('lift').value), yaw: Number($('yaw').value),
         pitch: Number($('pitch').value) });
}

function setSlider(input, value) {
  input.value = value;
  input.dispatchEvent(new Event('input'));
}

function sendCosmetic(values) {
  send({ t: 'cosmetic', values: values || cosmeticInputs.map((i) => Number(i.value)) });
}

// Run f(fraction done) -> cosmetic values for ms, then go back to the sliders' values.
function animate(ms, f) {
  clearInterval(animation);
  const start = performance.now();
  animation = setInterval(() => {
    const done = (performance.now() - start) / ms;
    if (done >= 1) { clearInterval(animation); sendCosmetic(); return; }
    sendCosmetic(f(done, cosmeticInputs.map((i) => Number(i.value))));
  }, ANIMATION_MS);
}

function led(hex, brightness) {
  const rgb = parseInt(hex.slice(1), 16);
  return ((brightness << 24) | rgb) >>> 0;
}

function sendLeds() {
  const b = Number($('led_bright').value);
  const side = ['front', 'middle', 'rear'].map((p) => led($('led_' + p).value, b));
  send({ t: 'illum', leds: [...side, ...side] });  // left and right mirrored, as the MDK GUI
}

function ledPreset(colours, brightness) {
  ['front', 'middle', 'rear'].forEach((p, i) => { $('led_' + p).value = colours[i]; });
  setSlider($('led_bright'), brightness);  // its value shown, and the LEDs sent
}

// The simulator's real_time_factor as last set or read, in the speed menu.
function showRtfSet(value) {
  const menu = $('rtf_set');
  if (typeof value !== 'number' || !Number.isFinite(value) || document.activeElement === menu) return;
  const text = String(value);
  if (![...menu.options].some((o) => Number(o.value) === value)) {
    menu.add(new Option(`${text}x`, text));
  }
  menu.value = [...menu.options].find((o) => Number(o.value) === value).value;
}

function batteryMarks(marks) {
  const [, , lo, hi] = READOUTS[0];
  const bar = readoutCells[0][1].parentElement;
  for (const volts of marks || []) {
    if (!Number.isFinite(volts)) continue;
    const mark = document.createElement('div');
    mark.className = 'mark';
    mark.title = `${volts} V`;
    mark.style.left = `${(100 * (volts - lo)) / (hi - lo)}%`;
    bar.appendChild(mark);
  }
}

function setUp(config) {
  gui.config = config;
  channels = config.channels;
  if ($('headsliders').childElementCount) return;  // a reconnection: the controls are there
  batteryMarks(config.battery_marks);
  setUpHearing(config);
  setUpDemo(config);
  if (config.touch && config.touch.rows > 0 && config.touch.columns > 0) {
    touchGrid = { rows: config.touch.rows, columns: config.touch.columns };
    drawBodyMap();
  }
  for (const [id, max] of [['linear', config.max_linear], ['angular', config.max_angular]]) {
    $(id).max = max;
    $(id).value = max / 2;
  }
  ['linear', 'angular', 'wagperiod', 'led_bright'].forEach(showValue);
  for (const joint of ['lift', 'yaw', 'pitch']) {
    const [lo, hi] = config.head[joint];
    slider($('headsliders'), joint, joint, lo, hi, 1, config.head_calib[joint], sendHead);
  }
  $('calib').addEventListener('click', () => {
    ['lift', 'yaw', 'pitch'].forEach((j) => setSlider($(j), config.head_calib[j]));
  });
  cosmeticInputs = COSMETIC.map((label, i) =>
    slider($('cossliders'), 'cos' + i, label, 0, 1, 0.01, config.cosmetic_calib[i], () => sendCosmetic()));
  $('coscalib').addEventListener('click', () => {
    cosmeticInputs.forEach((input, i) => { input.value = config.cosmetic_calib[i]; });
    sendCosmetic();
  });
  const tick = config.tick_s * 1000;
  $('blink').addEventListener('click', () => animate(40 * tick, (x, v) => {
    const closed = Math.sin(Math.PI * x);
    return v.map((value, i) => (i === 2 || i === 3 ? Math.max(value, closed) : value));
  }));
  $('wag').addEventListener('click', () => animate(80 * tick, (x, v) => {
    const phase = (2 * Math.PI * x * 80 * config.tick_s) / Number($('wagperiod').value);
    return v.map((value, i) => (i === 1 ? 0.5 + 0.5 * Math.sin(phase) : value));
  }));
  $('wiggle').addEventListener('click', () => animate(40 * tick, (x, v) =>
    v.map((value, i) => (i >= 4 ? Math.min(1, Math.max(0, value + 0.3 * Math.sin(4 * Math.PI * x))) : value))));
  for (const p of ['front', 'middle', 'rear']) $('led_' + p).addEventListener('input', sendLeds);
  $('led_bright').addEventListener('input', sendLeds);
  $('led_off').addEventListener('click', () => ledPreset(['#000000', '#000000', '#000000'], 0));
  $('led_white').addEventListener('click', () => ledPreset(['#ffffff', '#ffffff', '#ffffff'], 63));
  $('led_rgb').addEventListener('click', () => ledPreset(['#ff0000', '#00ff00', '#0000ff'], 255));
  const tone = config.tone;
  for (const [id, [lo, hi]] of [['tone_hz', tone.hz], ['tone_volume', tone.volume], ['tone_ticks', tone.ticks]]) {
    Object.assign($(id), { min: lo, max: hi });
  }
  for (const button of document.querySelectorAll('button.tone')) {
    button.addEventListener('click', () => send({ t: 'tone', values: button.dataset.tone.split(',').map(Number) }));
  }
  $('tone_play').addEventListener('click', () => send({ t: 'tone', values:
    ['tone_hz', 'tone_volume', 'tone_ticks'].map((id) => Math.round(Number($(id).value))) }));
  $('cliff').addEventListener('change', () => send({ t: 'flags', cliff_reflex: $('cliff').checked }));
}

function setUpSimulator() {
  $('pause').addEventListener('click', () =>
    send({ t: 'sim', action: gui.state && gui.state.sim.paused ? 'resume' : 'pause' }));
  $('step').addEventListener('click', () => send({ t: 'sim', action: 'step' }));
  $('reset').addEventListener('click', () => send({ t: 'sim', action: 'reset' }));
  $('robot').addEventListener('change', () => send({ t: 'robot', name: $('robot').value }));
  $('rtf_set').addEventListener('change', () => {
    send({ t: 'rtf', value: Number($('rtf_set').value) });
    $('rtf_set').blur();  // shown as the simulator says from now on
  });
}

function showMeasured() {
  const r = gui.state && gui.state.readouts;
  if (!r || !r.head) return;
  ['lift', 'yaw', 'pitch'].forEach((joint, i) => {
    const span = $(joint + '_measured');
    if (span && typeof r.head[i] === 'number') span.textContent = `(${fixed(r.head[i], 1)})`;
  });
}

buildReadouts();
setUpDriving();
setUpSimulator();
setUpBodyMap();
setUpSound();
setInterval(showMeasured, 100);
connect();
startWorld();
