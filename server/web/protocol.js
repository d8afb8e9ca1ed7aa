// SPDX-License-Identifier: MIT
// The viewer's model and protocol (docs/protocol.md): the world as the frames tell it (S), the
// requests sent, and the snapshot, JSON frames and binary frames read into S. What is not the
// model's (panels for the views, the status line for errors) is reached through `hooks`.

export const BUCKETS = 9;  // ball colours, slow (blue) to fast (red)

export const params = new URLSearchParams(location.search);

export const hooks = {
  views: (views) => {},  // the views changed (panels.js)
  error: (text) => {},   // an error reply, for the status line (viewer.js)
};

// ---- the world as the frames tell it -------------------------------------------------------
export const S = {
  world: null, arena: {width: 500, height: 400}, walls: [], views: [],
  balls: {n: 0, ids: [], radius: new Float32Array(0), pos: new Float32Array(0), vel: null, dead: new Set()},
  bucketOf: new Uint8Array(0), buckets: [], speedScale: 1,
  turtles: [], t: 0, step: 0, paused: false, speed: 1, simEvents: null,
  replay: null,  // a replay's {end, reverse, complete} (the status's "replay"); null: a live world
  lastSeq: 0, dropped: 0, framesIn: 0, bytesIn: 0, dirty: true, ended: null,
};
export const stats = {frames: [], draws: [], events: []};  // [wall ms, value] samples of the last seconds
let ws = null;
let nextId = 1;
const pending = new Map();  // request id -> callback

// ---- protocol ------------------------------------------------------------------------------
export function send(message, done) {
  if (!ws || ws.readyState !== 1) return;
  const id = nextId++;
  message.id = id;
  if (done) pending.set(id, done);
  ws.send(JSON.stringify(message));
}

export function connect() {
  const url = (location.protocol === 'https:' ? 'wss://' : 'ws://') + location.host + '/ws';
  ws = new WebSocket(url);
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => {
    const hello = {type: 'hello', protocol: 'turtlegas/1'};
    if (params.get('token')) hello.token = params.get('token');
    send(hello);
  };
  ws.onmessage = (e) => {
    if (typeof e.data !== 'string') return onBinaryFrame(e.data);
    S.bytesIn += e.data.length;
    const m = JSON.parse(e.data);
    if (m.id !== undefined && pending.has(m.id)) {
      pending.get(m.id)(m);
      pending.delete(m.id);
    }
    switch (m.type) {
      case 'welcome': onWelcome(m); break;
      case 'snapshot': onSnapshot(m); break;
      case 'frame': onJsonFrame(m); break;
      case 'status': case 'ok': if (m.status) onStatus(m.status); break;
      case 'world': S.world = m.world; break;
      case 'error': console.warn('turtlegas:', m.code, m.message); hooks.error(m.message); break;
      case 'bye': S.ended = 'server stopped (' + m.reason + ')'; break;
    }
  };
  ws.onclose = () => {
    S.ended = S.ended || 'disconnected';
    S.dirty = true;
  };
}

export function subscribe() {
  const binary = document.getElementById('binary').checked;
  send({type: 'subscribe', rate: Number(params.get('rate') || 30), format: binary ? 'binary' : 'json',
        events: ['touch', 'tag', 'view', 'wall-drawn', 'wall-added', 'sense'], velocities: true});
}

function onWelcome(m) {
  S.world = m.world;
  document.getElementById('world-name').textContent = m.world.name || 'turtlegas';
  document.title = (m.world.name || 'turtlegas') + ' - turtlegas viewer';
  onStatus(m.status);
  subscribe();
}

function onStatus(st) {
  S.paused = !!st.paused;
  S.speed = st.speed;
  S.ended = st.ended;
  S.t = st.t;
  S.replay = st.replay || null;
  const sel = document.getElementById('speed');
  if (String(st.speed) !== sel.value && [...sel.options].some((o) => o.value === String(st.speed))) sel.value = String(st.speed);
  S.dirty = true;
}

function readWall(w) {
  const layers = w.layers || [1, 0xffffffff];
  return {id: w.id, from: w.from, to: w.to, cat: layers[0] >>> 0, mask: layers[1] >>> 0, keys: w.keys || null,
          visibility: w.visibility || null};
}

function onSnapshot(m) {
  S.arena = m.arena;
  S.walls = m.walls.map(readWall);
  const b = m.balls;
  S.balls.n = b.ids.length;
  S.balls.ids = b.ids;
  S.balls.radius = Float32Array.from(b.radius);
  S.balls.pos = Float32Array.from(b.pos);
  S.balls.vel = b.vel ? Float32Array.from(b.vel) : null;
  S.balls.dead = new Set(b.dead);
  const names = new Map(), senses = new Map();
  for (const t of (S.world && S.world.turtles) || []) {
    names.set(t.id, t.sensors);
    senses.set(t.id, new Map((t.senses || []).map((r) => [r.name, r])));
  }
  S.turtles = m.turtles.map((t) => ({
    id: t.id, radius: t.radius, x: t.pos[0], y: t.pos[1], heading: t.heading, pen: t.pen, it: t.it,
    remote: t.remote, claimed: t.claimed, finished: t.finished, gone: !!t.gone,
    cat: t.layers ? t.layers[0] >>> 0 : 1, mask: t.layers ? t.layers[1] >>> 0 : 0xffffffff,
    arcs: t.arcs || [], sensorNames: names.get(t.id) || [], flash: new Map(),
    senses: senses.get(t.id) || new Map(), readings: new Map(),
    trail: t.trail.slice(),
  }));
  hooks.views(m.views || []);
  applyClock(m.t, m.step, m.paused, m.speed, m.sim_events);
  S.lastSeq = 0;
  updateBuckets();
  S.dirty = true;
}

function applyClock(t, step, paused, speed, simEvents) {
  S.t = t;
  S.step = step;
  S.paused = paused;
  if (speed !== undefined) S.speed = speed;
  if (simEvents !== undefined && simEvents !== null) {
    S.simEvents = simEvents;
    stats.events.push([performance.now(), simEvents]);
  }
}

function countFrame(seq, bytes) {
  if (S.lastSeq && seq > S.lastSeq + 1) S.dropped += seq - S.lastSeq - 1;
  S.lastSeq = seq;
  S.framesIn++;
  S.bytesIn += bytes;
  stats.frames.push([performance.now(), 1]);
}

/// Trails and walls come by parts: a count below `from` means a frame was missed.
function applyParts(trails, wallsFrom, walls) {
  let resync = false;
  trails.forEach((part, i) => {
    const t = S.turtles[i];
    if (!t) return;
    if (part.from > t.trail.length) resync = true;
    else {
      t.trail.length = part.from;
      for (const p of part.points) t.trail.push(p);
    }
  });
  if (wallsFrom > S.walls.length) resync = true;
  else if (walls.length) {
    S.walls.length = wallsFrom;
    for (const w of walls) S.walls.push(readWall(w));
  }
  if (resync) send({type: 'snapshot'});
}

function applyEvents(events) {
  const now = performance.now();
  for (const e of events) {
    if (e.kind === 'sense') { applyReading(e); continue; }
    if (e.kind !== 'touch') continue;
    const t = S.turtles.find((x) => x.id === e.a);
    if (!t) continue;
    for (const name of e.sensors || []) {
      const k = t.sensorNames.indexOf(name);
      if (k >= 0) t.flash.set(k, now);
    }
  }
}

/// A range sensor's reading (a `sense` event): kept, per sensor, with the turtle's pose in the frame
/// that brought it (its rays are drawn from there, while the turtle stays at that pose).
function applyReading(e) {
  const t = S.turtles.find((x) => x.id === e.a);
  const sensor = t && t.senses.get(e.sensor);
  if (!sensor) return;
  t.readings.set(e.sensor, {range: e.range, hit: e.hit, bearings: sensor.bearings, max: sensor.range,
                            x: t.x, y: t.y, heading: t.heading, t: e.t});
}

function onJsonFrame(m) {
  countFrame(m.seq, 0);
  applyClock(m.t, m.step, m.paused, m.speed, m.sim_events);
  const b = m.balls;
  if (!b.index && b.pos.length === 2 * S.balls.n) {
    S.balls.pos.set(b.pos);
    if (b.vel && S.balls.vel) S.balls.vel.set(b.vel);
  }
  S.balls.dead = new Set(b.dead);
  m.turtles.forEach((u, i) => {
    const t = S.turtles[i];
    if (!t) return;
    Object.assign(t, {x: u.pos[0], y: u.pos[1], heading: u.heading, pen: u.pen, it: u.it, remote: u.remote,
                      claimed: u.claimed, finished: u.finished, gone: !!u.gone});
  });
  applyParts(m.turtles.map((u) => ({from: u.trail_from, points: u.trail})), m.walls_from, m.walls);
  applyEvents(m.events);
  if (m.views) hooks.views(m.views);
  updateBuckets();
  S.dirty = true;
}

function onBinaryFrame(buf) {
  const dv = new DataView(buf);
  if (dv.getUint32(0, true) !== 0x31464754) return;  // "TGF1"
  const flags = dv.getUint16(6, true);
  const seq = dv.getUint32(8, true), n = dv.getUint32(12, true), m = dv.getUint32(16, true), L = dv.getUint32(20, true);
  countFrame(seq, buf.byteLength);
  let off = 48;
  let index = null;
  if (flags & 4) { index = new Uint32Array(buf, off, n); off += 4 * n; }
  const pos = new Float32Array(buf, off, 2 * n); off += 8 * n;
  let vel = null;
  if (flags & 2) { vel = new Float32Array(buf, off, 2 * n); off += 8 * n; }
  const tur = new Float32Array(buf, off, 3 * m); off += 12 * m;
  const tflags = new Uint32Array(buf, off, m); off += 4 * m;
  const tail = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, off, L)));
  if (!index && n === S.balls.n) {
    S.balls.pos.set(pos);
    if (vel && S.balls.vel) S.balls.vel.set(vel);
    const dead = new Set();
    for (let i = 0; i < n; i++) if (pos[2 * i] !== pos[2 * i]) dead.add(i);  // NaN
    S.balls.dead = dead;
  }
  for (let i = 0; i < m && i < S.turtles.length; i++) {
    const t = S.turtles[i], f = tflags[i];
    t.x = tur[3 * i]; t.y = tur[3 * i + 1]; t.heading = tur[3 * i + 2];
    t.pen = (f & 1) ? ((f & 2) ? 'wall' : 'line') : 'up';
    t.it = !!(f & 4); t.remote = !!(f & 8); t.claimed = !!(f & 16); t.finished = !!(f & 32); t.gone = !!(f & 64);
  }
  applyClock(dv.getFloat64(24, true), Number(dv.getBigUint64(40, true)), !!(flags & 1), undefined, tail.sim_events);
  applyParts(tail.trails, tail.walls_from, tail.walls);
  applyEvents(tail.events);
  if (tail.views) hooks.views(tail.views);
  updateBuckets();
  S.dirty = true;
}

/// Each ball's colour bucket, by speed relative to a scale that follows the gas (twice its RMS
/// speed, smoothed), and the balls of each bucket.
function updateBuckets() {
  const n = S.balls.n, vel = S.balls.vel;
  if (S.bucketOf.length !== n) S.bucketOf = new Uint8Array(n);
  const counts = new Uint32Array(BUCKETS);
  if (vel) {
    let sum = 0;
    for (let i = 0; i < n; i++) sum += vel[2 * i] * vel[2 * i] + vel[2 * i + 1] * vel[2 * i + 1];
    const rms = n ? Math.sqrt(sum / n) : 0;
    if (rms > 0) S.speedScale = S.speedScale === 1 ? 2 * rms : 0.9 * S.speedScale + 0.1 * 2 * rms;
    const k = (BUCKETS - 1) / S.speedScale;
    for (let i = 0; i < n; i++) {
      const s = Math.sqrt(vel[2 * i] * vel[2 * i] + vel[2 * i + 1] * vel[2 * i + 1]);
      const b = Math.min(BUCKETS - 1, Math.floor(s * k + 0.5));
      S.bucketOf[i] = b;
      counts[b]++;
    }
  }
  if (!S.buckets.length || S.buckets.length !== BUCKETS) S.buckets = Array.from({length: BUCKETS}, () => new Uint32Array(0));
  for (let b = 0; b < BUCKETS; b++) if (S.buckets[b].length < counts[b]) S.buckets[b] = new Uint32Array(Math.max(counts[b], 2 * S.buckets[b].length));
  const fill = new Uint32Array(BUCKETS);
  for (let i = 0; i < n; i++) { const b = S.bucketOf[i]; S.buckets[b][fill[b]++] = i; }
  S.bucketCounts = fill;
  document.getElementById('legend-hi').textContent = S.speedScale.toPrecision(3);
  document.getElementById('legend').hidden = n === 0;  // no balls: no speed scale to explain
}

