// SPDX-License-Identifier: MIT
// The turtlegas viewer (docs/viewer.md): one panel per view of the world, drawn on canvas from
// the frames of `turtlegas serve` (docs/protocol.md). ES modules, no build step:
//   protocol.js  the model (S) and the protocol: requests, snapshots, JSON and binary frames
//   geometry.js  the views' geometry (turtle/view.hpp): layers, transforms, wall poses
//   panels.js    the panels, docked or popped out, and the pointer that opens views
//   draw.js      one panel's canvas
//   viewer.js    (this) the status line, the one animation loop, the controls, the start
import {BUCKET_COLOURS, drawPanel} from './draw.js';
import {pixelMatrix, transformOf} from './geometry.js';
import {dock, layoutPanels, panels, setViews, showArena} from './panels.js';
import {BUCKETS, S, connect, hooks, params, send, stats, subscribe} from './protocol.js';

const bench = params.get('bench') === '1';  // draw every animation frame (bench/viewer_bench.py)

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
  const mode = S.replay ? (S.paused ? '' : S.replay.reverse ? '  REVERSE' : '') : '';
  let s = `t=${S.t.toFixed(2)} s  speed ${speed}${S.paused ? '  PAUSED' : ''}${mode}  events/s ${eps.toFixed(0)}  ` +
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
const resized = () => { layoutPanels(); S.dirty = true; };
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
  updateReplay();
  requestAnimationFrame(frame);
}

if (params.get('json') === '1') document.getElementById('binary').checked = false;

// ---- a replay: the REPLAY mark, reverse and the timeline ------------------------------------
// Shown when the status carries "replay" (`turtlegas replay R.tgrec`). Dragging the timeline
// seeks: one seek in flight at a time, the latest position sent when it is answered, so a fast
// drag never queues seeks behind each other; the knob follows the clock again once let go.
let dragging = false, seekBusy = false, seekWanted = null;

function seekTo(t) {
  seekWanted = t;
  if (seekBusy) return;
  seekBusy = true;
  const target = seekWanted;
  seekWanted = null;
  send({type: 'seek', t: target}, () => {
    seekBusy = false;
    if (seekWanted !== null) seekTo(seekWanted);
  });
}

let replayShown = false;
function updateReplay() {
  const r = S.replay;
  if (!!r !== replayShown) {
    replayShown = !!r;
    document.getElementById('replay-bar').hidden = !r;
    document.body.classList.toggle('replay', !!r);
    document.title = (r ? 'REPLAY - ' : '') + ((S.world && S.world.name) || 'turtlegas') + ' - turtlegas viewer';
    layoutPanels();
  }
  if (!r) return;
  const tl = document.getElementById('timeline');
  if (tl.max !== String(r.end)) tl.max = String(r.end);
  if (!dragging && !seekBusy && Number(tl.value) !== S.t) tl.value = String(S.t);
  const text = `${S.t.toFixed(2)} / ${r.end.toFixed(2)} s${r.complete ? '' : ' (cut)'}`;
  const label = document.getElementById('replay-time');
  if (label.textContent !== text) label.textContent = text;
  document.getElementById('reverse').classList.toggle('on', !!r.reverse && !S.paused);
}

function wireReplay() {
  const tl = document.getElementById('timeline');
  tl.addEventListener('pointerdown', () => { dragging = true; });
  tl.addEventListener('input', () => { dragging = true; seekTo(Number(tl.value)); });
  tl.addEventListener('change', () => { dragging = false; seekTo(Number(tl.value)); });
  window.addEventListener('pointerup', () => { dragging = false; });
  document.getElementById('reverse').onclick = () => send({type: 'reverse'});
}

// ---- controls ------------------------------------------------------------------------------
function wire() {
  document.getElementById('pause').onclick = () => send({type: 'pause'});
  document.getElementById('resume').onclick = () => send({type: 'resume'});  // a replay: forward
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
    if (e.key === 'r' && S.replay) send({type: 'reverse'});
  });
  const legend = document.getElementById('legend-bar').getContext('2d');
  for (let k = 0; k < BUCKETS; k++) {
    legend.fillStyle = BUCKET_COLOURS[k];
    legend.fillRect(k * 120 / BUCKETS, 0, 120 / BUCKETS + 1, 10);
  }
}

// For tests and benchmarks: the state, the panels, and the geometry the pixels follow.
window.turtlegasViewer = {
  state: S, panels, transformOf: (view) => transformOf(view, S.turtles), pixelMatrix, send,
  stats: () => ({framesIn: S.framesIn, dropped: S.dropped, t: S.t, paused: S.paused,
                 draws: Object.fromEntries([...panels].map(([id, p]) => [id, p.draws.length]))}),
  showArena, seekTo,
};

hooks.views = setViews;
hooks.error = flashStatus;
wire();
wireReplay();
connect();
requestAnimationFrame(frame);
