// SPDX-License-Identifier: MIT
// The viewer's panels: one per view of the world (the views the server shares, and this viewer's
// own whole-arena panel when there is none or it is asked for), docked in the page or popped out
// into a window of their own; a click on a turtle opens a view following it, a drag a fixed view.

import {invert} from './geometry.js';
import {S, send} from './protocol.js';

export const panels = new Map();  // id -> panel
let localShown = null;     // whether the local whole-arena panel is wanted (null: when no view shows the room)

function localView() {
  return {id: 'arena', local: true, center: [S.arena.width / 2, S.arena.height / 2],
          size: [S.arena.width * 1.04, S.arena.height * 1.04], title: 'the whole arena (this viewer only)', layers: 'all'};
}

export function setViews(views) {
  S.views = views;
  syncPanels();
}

export function syncPanels() {
  const wanted = new Map();
  // Shown by default when no view shows the room: no view at all, or only views that follow a
  // turtle (a recording whose one view is a follow camera would otherwise never show the room).
  const showLocal = localShown === null ? S.views.every((v) => v.follow) : localShown;
  if (showLocal) wanted.set('arena', localView());
  for (const v of S.views) wanted.set(v.id, v);
  for (const [id, p] of panels) if (!wanted.has(id)) removePanel(p);
  for (const [id, v] of wanted) {
    const p = panels.get(id);
    if (p) p.view = v; else panels.set(id, makePanel(v));
  }
  layoutPanels();
  S.dirty = true;
}

/// The docked panels share the window: the grid (columns × rows) that draws the views largest,
/// each view fitted to its cell at its own aspect (at least 360 × 320 px a cell; more rows scroll).
/// One panel fills the page; four views of a room make two rows of two, not four thin columns.
export function layoutPanels() {
  const box = document.getElementById('panels');
  const docked = [...panels.values()].filter((p) => !p.popup);
  const gap = 8, chrome = 52;  // a panel's title bar and status line, px
  const width = box.clientWidth - 2 * gap, height = box.clientHeight - 2 * gap;
  let best = {cols: 1, rows: Math.max(1, docked.length), area: -1, rowHeight: 320};
  for (let cols = 1; cols <= Math.max(1, docked.length); cols++) {
    const rows = Math.max(1, Math.ceil(docked.length / cols));
    const cw = (width - (cols - 1) * gap) / cols;
    if (cols > 1 && cw < 360) break;
    const rowHeight = Math.max(320, Math.floor((height - (rows - 1) * gap) / rows));
    const ch = rowHeight - chrome;
    let area = 0;
    for (const p of docked) {
      const a = p.view.size[0] / p.view.size[1];
      area += a > cw / ch ? cw * cw / a : ch * ch * a;
    }
    if (area > best.area * 1.001) best = {cols, rows, area, rowHeight};
  }
  box.style.gridTemplateColumns = `repeat(${best.cols}, minmax(0, 1fr))`;
  box.style.gridAutoRows = `${best.rowHeight}px`;
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
  layoutPanels();
}

export function dock(p) {
  if (!panels.has(p.id)) return;
  document.getElementById('panels').appendChild(document.adoptNode(p.el));
  p.popup = null;
  layoutPanels();
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


/// Shows (true) or hides (false) the whole-arena panel; null: shown when the server has no view.
export function showArena(on) {
  localShown = on;
  syncPanels();
}
