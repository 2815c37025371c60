// The MiRo GUI page: images and readouts in, commands out, over one WebSocket.
// The server sends the newest frame of each channel and waits for our 'ack' before
// the next, so frames never pile up here. Driving is a command refreshed every
// DRIVE_REFRESH_MS while a key or button is held; the server stops the robot when the
// refreshes stop (key up, page hidden or closed, connection lost).
'use strict';

const DRIVE_REFRESH_MS = 100;
const ANIMATION_MS = 40;  // cosmetic animations: 25 updates a second
const DEBUG_FRESH_MS = 1000;  // show the controller's annotated frame while this fresh
const FPS_FRAMES = 15;  // the MDK GUI averages its frame rate over 15 frames
const LOG_LENGTH = 5000;
const $ = (id) => document.getElementById(id);

// What tests and the benchmark read: frames drawn per channel, and when.
const gui = window.miroGui = { frames: {}, drawn: [], state: null, config: null, connected: false };

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
  ws.onopen = () => { gui.connected = true; showConnection(); };
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
  if (message.t === 'config') setUp(message);
  else if (message.t === 'state') showState(message);
}

// ---- images --------------------------------------------------------------------------------
function onFrame(buffer) {
  const view = new DataView(buffer);
  const ch = view.getUint8(0);
  const stamp = view.getFloat64(1, true);
  const blob = new Blob([new Uint8Array(buffer, 9)], { type: 'image/jpeg' });
  createImageBitmap(blob)
    .then((bitmap) => { draw(channels[ch], stamp, bitmap); bitmap.close(); })
    .catch(() => {})  // a corrupt JPEG: skip it, the next one comes
    .finally(() => send({ t: 'ack', ch }));
}

function draw(name, stamp, bitmap) {
  const now = performance.now();
  let target = name;
  if (name.startsWith('debug_')) {
    target = name.slice(6);
    lastDebug[target] = now;
    if (!$('detections').checked) return;
  } else if (name !== 'overhead' && $('detections').checked
             && now - (lastDebug[name] || -1e9) < DEBUG_FRESH_MS) {
    return;  // this eye is shown with the controller's detections drawn
  }
  const canvas = $(target);
  if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {
    canvas.width = bitmap.width;
    canvas.height = bitmap.height;
  }
  const ctx = canvas.getContext('2d');
  ctx.drawImage(bitmap, 0, 0);
  if (target === 'overhead') $('overheadbox').hidden = false;
  else crossHairs(ctx, bitmap.width, bitmap.height, target === 'caml' ? 0.75 : 0.25);
  gui.frames[name] = (gui.frames[name] || 0) + 1;
  gui.drawn.push({ ch: name, stamp, at: performance.timeOrigin + now });
  if (gui.drawn.length > LOG_LENGTH) gui.drawn.splice(0, gui.drawn.length - LOG_LENGTH);
  const times = frameTimes[target] = frameTimes[target] || [];
  times.push(now);
  if (times.length > FPS_FRAMES) times.shift();
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
  gui.state = state;
  showReadouts(state.readouts || {});
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
  $('status').textContent = state.status;
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
  $('led_bright').value = brightness;
  sendLeds();
}

function setUp(config) {
  gui.config = config;
  channels = config.channels;
  if ($('headsliders').childElementCount) return;  // a reconnection: the controls are there
  for (const [id, max] of [['linear', config.max_linear], ['angular', config.max_angular]]) {
    $(id).max = max;
    $(id).value = max / 2;
    $(id + '_out').textContent = Number($(id).value).toFixed(2);
    $(id).addEventListener('input', () => { $(id + '_out').textContent = Number($(id).value).toFixed(2); });
  }
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
setInterval(showMeasured, 100);
connect();
