// SPDX-License-Identifier: MIT
// The turtlegas viewer (docs/viewer.md): one panel per view of the world, drawn on canvas from
// the frames of `turtlegas serve` (docs/protocol.md). Plain JavaScript, no build step.
//
// Geometry is that of turtle/view.hpp: a view shows [-w/2, w/2] x [-h/2, h/2] around its centre in
// view coordinates (x right, y up); a fixed view's centre is `center`, a follow view's the followed
// turtle plus `offset` (in its frame, and turned with it, when `rotate`). Each view's canvas has the
// view's aspect ratio, so world point p lands on canvas pixel
//   ((v.x / w + 0.5) * canvas.width, (0.5 - v.y / h) * canvas.height),   v = p in view coordinates.
'use strict';

(function () {
  const COLOURS = {
    background: '#f8f8f4', wall: '#222222', turtle: '#1d7f74', it: '#d62828', remote: '#6a4c93',
    heading: '#ffffff', outline: '#0b3d38', trail: 'rgba(40, 90, 200, 0.85)', flash: 'rgba(255, 160, 0, 0.9)',
  };
  const LAYERS = ['walls', 'balls', 'turtles', 'trails', 'sensors', 'roles'];
  const ALL_LAYERS = (1 << LAYERS.length) - 1;
  const BUCKETS = 9;  // ball colours, slow (blue) to fast (red)
  const FLASH_MS = 400;

  const params = new URLSearchParams(location.search);
  const bench = params.get('bench') === '1';  // draw every animation frame (bench/viewer_bench.py)

  // ---- the world as the frames tell it -------------------------------------------------------
  const S = {
    world: null, arena: {width: 500, height: 400}, walls: [], views: [],
    balls: {n: 0, ids: [], radius: new Float32Array(0), pos: new Float32Array(0), vel: null, dead: new Set()},
    bucketOf: new Uint8Array(0), buckets: [], speedScale: 1,
    turtles: [], t: 0, step: 0, paused: false, speed: 1, simEvents: null,
    lastSeq: 0, dropped: 0, framesIn: 0, bytesIn: 0, dirty: true, ended: null,
  };
  const stats = {frames: [], draws: [], events: []};  // [wall ms, value] samples of the last seconds
  let ws = null;
  let nextId = 1;
  const pending = new Map();  // request id -> callback

  function bucketColour(k) {
    // A blue-green-yellow-red ramp.
    const x = k / (BUCKETS - 1);
    const h = 240 - 240 * x;
    return `hsl(${h.toFixed(0)}, 80%, ${(45 + 5 * Math.sin(Math.PI * x)).toFixed(0)}%)`;
  }
  const BUCKET_COLOURS = Array.from({length: BUCKETS}, (_, k) => bucketColour(k));

  // ---- protocol ------------------------------------------------------------------------------
  function send(message, done) {
    if (!ws || ws.readyState !== 1) return;
    const id = nextId++;
    message.id = id;
    if (done) pending.set(id, done);
    ws.send(JSON.stringify(message));
  }

  function connect() {
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
        case 'error': console.warn('turtlegas:', m.code, m.message); flashStatus(m.message); break;
        case 'bye': S.ended = 'server stopped (' + m.reason + ')'; break;
      }
    };
    ws.onclose = () => {
      S.ended = S.ended || 'disconnected';
      S.dirty = true;
    };
  }

  function subscribe() {
    const binary = document.getElementById('binary').checked;
    send({type: 'subscribe', rate: Number(params.get('rate') || 30), format: binary ? 'binary' : 'json',
          events: ['touch', 'tag', 'view', 'wall-drawn', 'wall-added'], velocities: true});
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
    const names = new Map();
    for (const t of (S.world && S.world.turtles) || []) names.set(t.id, t.sensors);
    S.turtles = m.turtles.map((t) => ({
      id: t.id, radius: t.radius, x: t.pos[0], y: t.pos[1], heading: t.heading, pen: t.pen, it: t.it,
      remote: t.remote, claimed: t.claimed, finished: t.finished,
      cat: t.layers ? t.layers[0] >>> 0 : 1, mask: t.layers ? t.layers[1] >>> 0 : 0xffffffff,
      arcs: t.arcs || [], sensorNames: names.get(t.id) || [], flash: new Map(),
      trail: t.trail.slice(),
    }));
    setViews(m.views || []);
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
      if (e.kind !== 'touch') continue;
      const t = S.turtles.find((x) => x.id === e.a);
      if (!t) continue;
      for (const name of e.sensors || []) {
        const k = t.sensorNames.indexOf(name);
        if (k >= 0) t.flash.set(k, now);
      }
    }
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
                        claimed: u.claimed, finished: u.finished});
    });
    applyParts(m.turtles.map((u) => ({from: u.trail_from, points: u.trail})), m.walls_from, m.walls);
    applyEvents(m.events);
    if (m.views) setViews(m.views);
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
      t.it = !!(f & 4); t.remote = !!(f & 8); t.claimed = !!(f & 16); t.finished = !!(f & 32);
    }
    applyClock(dv.getFloat64(24, true), Number(dv.getBigUint64(40, true)), !!(flags & 1), undefined, tail.sim_events);
    applyParts(tail.trails, tail.walls_from, tail.walls);
    applyEvents(tail.events);
    if (tail.views) setViews(tail.views);
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
  }

  // ---- views and their geometry (turtle/view.hpp) ----------------------------------------------
  function layerBits(names) {
    if (names === 'all' || names === undefined) return ALL_LAYERS;
    let bits = 0;
    for (const n of names) { const k = LAYERS.indexOf(n); if (k >= 0) bits |= 1 << k; }
    return bits;
  }

  function transformOf(view) {
    const size = view.size || [200, 200];
    let center = view.center || [0, 0], right = [1, 0], up = [0, 1];
    const t = view.follow ? S.turtles.find((x) => x.id === view.follow) : null;
    if (t) {
      const off = view.offset || [0, 0];
      if (view.rotate) {
        const h = t.heading * Math.PI / 180, s = Math.sin(h), c = Math.cos(h);
        up = [s, c];
        right = [c, -s];
        center = [t.x + off[0] * right[0] + off[1] * up[0], t.y + off[0] * right[1] + off[1] * up[1]];
      } else {
        center = [t.x + off[0], t.y + off[1]];
      }
    }
    return {center, right, up, size, followed: t};
  }

  /// World to canvas pixels for canvas size W x H (the view stretched to it), as a 2-D matrix.
  function pixelMatrix(tf, W, H) {
    const kx = W / tf.size[0], ky = H / tf.size[1];
    const [cx, cy] = tf.center, [rx, ry] = tf.right, [ux, uy] = tf.up;
    return {a: kx * rx, b: -ky * ux, c: kx * ry, d: -ky * uy,
            e: W / 2 - kx * (cx * rx + cy * ry), f: H / 2 + ky * (cx * ux + cy * uy), k: kx};
  }
  const apply = (M, x, y) => [M.a * x + M.c * y + M.e, M.b * x + M.d * y + M.f];
  function invert(M, px, py) {
    const det = M.a * M.d - M.b * M.c;
    const x = px - M.e, y = py - M.f;
    return [(M.d * x - M.c * y) / det, (-M.b * x + M.a * y) / det];
  }

  /// A wall's ends at time t (its keys) and whether it is there (its visibility).
  function wallPose(w, t) {
    let from = w.from, to = w.to, present = true;
    if (w.keys) {
      let t0 = 0, f0 = w.from, e0 = w.to;
      from = null;
      for (const k of w.keys) {
        if (t < k[0]) {
          const s = (t - t0) / (k[0] - t0);
          from = [f0[0] + s * (k[1] - f0[0]), f0[1] + s * (k[2] - f0[1])];
          to = [e0[0] + s * (k[3] - e0[0]), e0[1] + s * (k[4] - e0[1])];
          break;
        }
        t0 = k[0]; f0 = [k[1], k[2]]; e0 = [k[3], k[4]];
      }
      if (!from) { from = f0; to = e0; }
    }
    if (w.visibility) for (const v of w.visibility) if (t >= v[0]) present = v[1];
    return {from, to, present};
  }

  // ---- panels --------------------------------------------------------------------------------
  const panels = new Map();  // id -> panel
  let localShown = null;     // whether the local whole-arena panel is wanted (null: when no view)

  function localView() {
    return {id: 'arena', local: true, center: [S.arena.width / 2, S.arena.height / 2],
            size: [S.arena.width * 1.04, S.arena.height * 1.04], title: 'the whole arena (this viewer only)', layers: 'all'};
  }

  function setViews(views) {
    S.views = views;
    syncPanels();
  }

  function syncPanels() {
    const wanted = new Map();
    const showLocal = localShown === null ? S.views.length === 0 : localShown;
    if (showLocal) wanted.set('arena', localView());
    for (const v of S.views) wanted.set(v.id, v);
    for (const [id, p] of panels) if (!wanted.has(id)) removePanel(p);
    for (const [id, v] of wanted) {
      const p = panels.get(id);
      if (p) p.view = v; else panels.set(id, makePanel(v));
    }
    S.dirty = true;
  }

  function makePanel(view) {
    const el = document.createElement('section');
    el.className = 'panel' + (view.local ? ' local' : '');
    el.dataset.view = view.id;
    el.innerHTML = '<header><span class="title"></span><button class="pop" title="into its own window">pop out</button>' +
                   '<button class="close" title="close this view">×</button></header><div class="stage"><canvas class="view"></canvas></div>' +
                   '<div class="vstatus status"></div>';
    document.getElementById('panels').appendChild(el);
    const canvas = el.querySelector('canvas');
    canvas.dataset.view = view.id;
    const p = {id: view.id, view, el, canvas, ctx: canvas.getContext('2d', {alpha: false}), popup: null, draws: [], matrix: null};
    el.querySelector('.close').onclick = () => {
      if (p.view.local) { localShown = false; syncPanels(); } else send({type: 'view_close', view: p.id});
    };
    el.querySelector('.pop').onclick = () => popOut(p);
    attachPointer(p);
    return p;
  }

  function removePanel(p) {
    if (p.popup && !p.popup.closed) p.popup.close();
    p.el.remove();
    panels.delete(p.id);
  }

  function popOut(p) {
    if (p.popup && !p.popup.closed) { p.popup.focus(); return; }
    const w = window.open('', 'turtlegas-' + p.id, 'width=640,height=520');
    if (!w) return;
    w.document.title = (p.view.title || p.id) + ' - turtlegas';
    w.document.body.className = 'popout';
    const link = w.document.createElement('link');
    link.rel = 'stylesheet';
    link.href = new URL('viewer.css', location.href).href;
    w.document.head.appendChild(link);
    w.document.body.appendChild(w.document.adoptNode(p.el));
    p.popup = w;
    p.el.querySelector('.pop').textContent = 'dock';
    p.el.querySelector('.pop').onclick = () => w.close();
    w.addEventListener('pagehide', () => setTimeout(() => dock(p), 0));
  }

  function dock(p) {
    if (!panels.has(p.id)) return;
    document.getElementById('panels').appendChild(document.adoptNode(p.el));
    p.popup = null;
    p.el.querySelector('.pop').textContent = 'pop out';
    p.el.querySelector('.pop').onclick = () => popOut(p);
    S.dirty = true;
  }

  /// A click on a turtle opens a view following it (shift: turned with it); a drag, a fixed view.
  function attachPointer(p) {
    const c = p.canvas;
    let start = null, band = null;
    const local = (e) => {
      const r = c.getBoundingClientRect();
      return [(e.clientX - r.left) * c.width / r.width, (e.clientY - r.top) * c.height / r.height, e.clientX - r.left, e.clientY - r.top];
    };
    c.addEventListener('pointerdown', (e) => { start = local(e); c.setPointerCapture(e.pointerId); });
    c.addEventListener('pointermove', (e) => {
      if (!start) return;
      const q = local(e);
      if (!band && Math.hypot(q[2] - start[2], q[3] - start[3]) > 6) {
        band = c.ownerDocument.createElement('div');
        band.className = 'rubber';
        c.parentElement.appendChild(band);
      }
      if (band) {
        const off = c.offsetLeft, top = c.offsetTop;
        Object.assign(band.style, {left: off + Math.min(q[2], start[2]) + 'px', top: top + Math.min(q[3], start[3]) + 'px',
                                   width: Math.abs(q[2] - start[2]) + 'px', height: Math.abs(q[3] - start[3]) + 'px'});
      }
    });
    c.addEventListener('pointerup', (e) => {
      if (!start || !p.matrix) { start = null; return; }
      const q = local(e);
      if (band) {
        band.remove();
        band = null;
        const a = invert(p.matrix, start[0], start[1]), b = invert(p.matrix, q[0], q[1]);
        const k = p.matrix.k;
        const w = Math.abs(q[0] - start[0]) / k, h = Math.abs(q[1] - start[1]) / k;
        if (w > 0 && h > 0)
          send({type: 'view_open', view: {id: freshId('box'), center: [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2], size: [w, h],
                                          title: 'fixed ' + w.toFixed(0) + ' x ' + h.toFixed(0)}});
      } else {
        const [x, y] = invert(p.matrix, q[0], q[1]);
        const hit = S.turtles.find((t) => Math.hypot(t.x - x, t.y - y) <= t.radius + 4 / p.matrix.k);
        if (hit) {
          const size = [Math.max(4 * hit.radius, p.view.size[0] / 2), Math.max(4 * hit.radius, p.view.size[1] / 2)];
          send({type: 'view_open', view: {id: freshId(hit.id + (e.shiftKey ? '-turned' : '-follow')), follow: hit.id, offset: [0, 0],
                                          size, rotate: e.shiftKey, title: 'following ' + hit.id + (e.shiftKey ? ', turned' : '')}});
        }
      }
      start = null;
    });
  }

  function freshId(base) {
    if (!S.views.some((v) => v.id === base)) return base;
    for (let k = 2; ; k++) if (!S.views.some((v) => v.id === base + '-' + k)) return base + '-' + k;
  }

  // ---- drawing -------------------------------------------------------------------------------
  function fitCanvas(p) {
    const stage = p.canvas.parentElement;
    const W = stage.clientWidth, H = stage.clientHeight;
    if (W < 2 || H < 2) return false;
    const aspect = p.view.size[0] / p.view.size[1];
    let cw = W, ch = W / aspect;
    if (ch > H) { ch = H; cw = H * aspect; }
    const dpr = (p.popup || window).devicePixelRatio || 1;
    const pw = Math.max(1, Math.round(cw * dpr)), ph = Math.max(1, Math.round(ch * dpr));
    if (p.canvas.width !== pw || p.canvas.height !== ph) {
      p.canvas.width = pw;
      p.canvas.height = ph;
    }
    p.canvas.style.width = cw + 'px';
    p.canvas.style.height = ch + 'px';
    return true;
  }

  function drawPanel(p, now) {
    if (!fitCanvas(p)) return;
    const ctx = p.ctx, W = p.canvas.width, H = p.canvas.height, v = p.view;
    const layers = layerBits(v.layers);
    const tf = transformOf(v);
    const M = pixelMatrix(tf, W, H);
    p.matrix = M;
    const px = 1 / M.k;  // one pixel in world units
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.fillStyle = COLOURS.background;
    ctx.fillRect(0, 0, W, H);
    ctx.setTransform(M.a, M.b, M.c, M.d, M.e, M.f);
    // The world box in view: the circumscribed rectangle of the (maybe turned) view.
    const hw = tf.size[0] / 2, hh = tf.size[1] / 2;
    const ex = Math.abs(tf.right[0]) * hw + Math.abs(tf.up[0]) * hh, ey = Math.abs(tf.right[1]) * hw + Math.abs(tf.up[1]) * hh;
    const x0 = tf.center[0] - ex, x1 = tf.center[0] + ex, y0 = tf.center[1] - ey, y1 = tf.center[1] + ey;
    const followed = tf.followed;

    if (layers & 1) {  // walls
      ctx.lineCap = 'round';
      for (const w of S.walls) {
        const pose = wallPose(w, S.t);
        const passes = followed && !((w.cat & followed.mask) && (followed.cat & w.mask));
        ctx.strokeStyle = COLOURS.wall;
        ctx.globalAlpha = pose.present ? 1 : 0.35;
        ctx.lineWidth = 2.5 * px;
        ctx.setLineDash(passes || !pose.present ? [6 * px, 5 * px] : []);
        ctx.beginPath();
        ctx.moveTo(pose.from[0], pose.from[1]);
        ctx.lineTo(pose.to[0], pose.to[1]);
        ctx.stroke();
      }
      ctx.setLineDash([]);
      ctx.globalAlpha = 1;
    }
    if (layers & 2) drawBalls(ctx, px, x0, x1, y0, y1);
    if (layers & 8) {  // trails
      ctx.strokeStyle = COLOURS.trail;
      ctx.lineWidth = 1.5 * px;
      ctx.lineJoin = 'round';
      for (const t of S.turtles) {
        if (!t.trail.length) continue;
        ctx.beginPath();
        let gap = true;  // null in a trail: a break between strokes (pen lifted, or a teleport)
        for (const p of t.trail) {
          if (!p) { gap = true; continue; }
          if (gap) ctx.moveTo(p[0], p[1]); else ctx.lineTo(p[0], p[1]);
          gap = false;
        }
        if (t.pen !== 'up' && !gap) ctx.lineTo(t.x, t.y);
        ctx.stroke();
      }
    }
    if (layers & 4) {  // turtles
      for (const t of S.turtles) {
        if (t.x + t.radius < x0 || t.x - t.radius > x1 || t.y + t.radius < y0 || t.y - t.radius > y1) continue;
        ctx.fillStyle = (layers & 32) && t.it ? COLOURS.it : t.remote ? COLOURS.remote : COLOURS.turtle;
        ctx.beginPath();
        ctx.arc(t.x, t.y, t.radius, 0, 2 * Math.PI);
        ctx.fill();
        ctx.strokeStyle = COLOURS.outline;
        ctx.lineWidth = 1 * px;
        ctx.stroke();
        const h = t.heading * Math.PI / 180;
        ctx.strokeStyle = COLOURS.heading;
        ctx.lineWidth = Math.max(1.5 * px, t.radius / 6);
        ctx.beginPath();
        ctx.moveTo(t.x, t.y);
        ctx.lineTo(t.x + 0.95 * t.radius * Math.sin(h), t.y + 0.95 * t.radius * Math.cos(h));
        ctx.stroke();
        if (layers & 16) {  // the sensor arcs that fired, flashing
          for (const [k, at] of t.flash) {
            const age = now - at;
            if (age > FLASH_MS) { t.flash.delete(k); continue; }
            const arc = t.arcs[k];
            if (!arc) continue;
            ctx.strokeStyle = COLOURS.flash;
            ctx.globalAlpha = 1 - age / FLASH_MS;
            ctx.lineWidth = Math.max(3 * px, t.radius / 4);
            ctx.beginPath();
            ctx.arc(t.x, t.y, t.radius * 1.25, (90 - t.heading - arc[0]) * Math.PI / 180, (90 - t.heading - arc[1]) * Math.PI / 180, true);
            ctx.stroke();
            ctx.globalAlpha = 1;
            S.dirty = true;  // keep fading
          }
        }
        if ((layers & 32) && t.it) {  // the role, "it": a ring
          ctx.strokeStyle = COLOURS.it;
          ctx.lineWidth = 2 * px;
          ctx.beginPath();
          ctx.arc(t.x, t.y, t.radius + 4 * px, 0, 2 * Math.PI);
          ctx.stroke();
        }
      }
      // Labels in pixel space (text is never turned or mirrored).
      ctx.setTransform(1, 0, 0, 1, 0, 0);
      const dpr = W / parseFloat(p.canvas.style.width || W);
      ctx.font = `${(11 * dpr).toFixed(0)}px system-ui, sans-serif`;
      ctx.textAlign = 'center';
      for (const t of S.turtles) {
        const [qx, qy] = apply(M, t.x, t.y);
        if (qx < -20 || qx > W + 20 || qy < -20 || qy > H + 20) continue;
        const label = (layers & 32) && t.it ? t.id + ' (it)' : t.id;
        ctx.fillStyle = (layers & 32) && t.it ? COLOURS.it : '#333';
        ctx.fillText(label, qx, qy - (t.radius * M.k + 6 * dpr));
      }
    }
    ctx.setTransform(1, 0, 0, 1, 0, 0);
  }

  function drawBalls(ctx, px, x0, x1, y0, y1) {
    const b = S.balls, pos = b.pos, rad = b.radius;
    if (!b.n || !S.bucketCounts) return;
    for (let k = 0; k < BUCKETS; k++) {
      const list = S.buckets[k], count = S.bucketCounts[k];
      if (!count) continue;
      ctx.fillStyle = BUCKET_COLOURS[k];
      ctx.beginPath();
      for (let j = 0; j < count; j++) {
        const i = list[j];
        const x = pos[2 * i], y = pos[2 * i + 1], r = rad[i];
        if (!(x + r >= x0 && x - r <= x1 && y + r >= y0 && y - r <= y1)) continue;  // also NaN: dead
        if (r < 1.2 * px) {
          const s = Math.max(r, 0.75 * px);
          ctx.rect(x - s, y - s, 2 * s, 2 * s);
        } else {
          ctx.moveTo(x + r, y);
          ctx.arc(x, y, r, 0, 2 * Math.PI);
        }
      }
      ctx.fill();
    }
  }

  // ---- status lines --------------------------------------------------------------------------
  function rate(samples, now, sum) {
    while (samples.length && samples[0][0] < now - 2000) samples.shift();
    if (!sum) {
      if (samples.length < 2) return 0;
      const dt = (samples[samples.length - 1][0] - samples[0][0]) / 1000;
      return dt > 0 ? (samples[samples.length - 1][1] - samples[0][1]) / dt : 0;
    }
    const span = samples.length ? Math.max(0.5, (now - samples[0][0]) / 1000) : 1;
    return samples.length / span;
  }

  let statusMessage = '', statusUntil = 0;
  function flashStatus(text) { statusMessage = text; statusUntil = performance.now() + 4000; }

  function updateStatus(now) {
    const fps = rate(stats.frames, now, true), drawn = rate(stats.draws, now, true), eps = rate(stats.events, now, false);
    const speed = S.speed === 'max' ? 'max' : '×' + S.speed;
    let s = `t=${S.t.toFixed(2)} s  speed ${speed}${S.paused ? '  PAUSED' : ''}  events/s ${eps.toFixed(0)}  ` +
            `frames/s ${fps.toFixed(1)} (drawn ${drawn.toFixed(1)})  dropped ${S.dropped}`;
    if (S.ended) s += '  ended: ' + S.ended;
    if (now < statusUntil) s += '  ! ' + statusMessage;
    document.getElementById('status').textContent = s;
    for (const p of panels.values()) {
      const v = p.view, d = rate(p.draws, now, true);
      const where = v.follow ? `follow ${v.follow}${v.rotate ? ', turned' : ''}` : `centre [${v.center.map((x) => x.toFixed(0))}]`;
      p.el.querySelector('.title').textContent = v.title || v.id;
      p.el.querySelector('.vstatus').textContent =
          `${v.id}: ${where}  ${v.size[0].toFixed(0)}×${v.size[1].toFixed(0)} u  t=${S.t.toFixed(2)} s  ${d.toFixed(1)} fps`;
    }
  }

  // ---- the one animation loop ----------------------------------------------------------------
  let lastStatus = 0, lastDraw = 0;
  const resized = () => { S.dirty = true; };
  window.addEventListener('resize', resized);
  if (window.ResizeObserver) new ResizeObserver(resized).observe(document.getElementById('panels'));

  function frame(now) {
    if (S.dirty || bench || now - lastDraw > 1000) {
      S.dirty = false;
      lastDraw = now;
      for (const p of panels.values()) {
        if (p.popup && p.popup.closed) dock(p);
        drawPanel(p, now);
        p.draws.push([now, 1]);
        while (p.draws.length && p.draws[0][0] < now - 2000) p.draws.shift();
      }
      stats.draws.push([now, 1]);
    }
    if (now - lastStatus > 250) {
      lastStatus = now;
      updateStatus(now);
    }
    requestAnimationFrame(frame);
  }

  if (params.get('json') === '1') document.getElementById('binary').checked = false;

  // ---- controls ------------------------------------------------------------------------------
  function wire() {
    document.getElementById('pause').onclick = () => send({type: 'pause'});
    document.getElementById('resume').onclick = () => send({type: 'resume'});
    document.getElementById('step').onclick = () => send({type: 'step', steps: 1});
    document.getElementById('speed').onchange = (e) => {
      const v = e.target.value;
      send({type: 'speed', factor: v === 'max' ? 'max' : Number(v)});
    };
    document.getElementById('binary').onchange = () => subscribe();
    document.addEventListener('keydown', (e) => {
      if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
      if (e.key === ' ') { send({type: S.paused ? 'resume' : 'pause'}); e.preventDefault(); }
      if (e.key === 's') send({type: 'step', steps: 1});
    });
    const legend = document.getElementById('legend-bar').getContext('2d');
    for (let k = 0; k < BUCKETS; k++) {
      legend.fillStyle = BUCKET_COLOURS[k];
      legend.fillRect(k * 120 / BUCKETS, 0, 120 / BUCKETS + 1, 10);
    }
  }

  // For tests and benchmarks: the state, the panels, and the geometry the pixels follow.
  window.turtlegasViewer = {
    state: S, panels, transformOf, pixelMatrix, send,
    stats: () => ({framesIn: S.framesIn, dropped: S.dropped, t: S.t, paused: S.paused,
                   draws: Object.fromEntries([...panels].map(([id, p]) => [id, p.draws.length]))}),
    showArena: (on) => { localShown = on; syncPanels(); },
  };

  wire();
  connect();
  requestAnimationFrame(frame);
})();
