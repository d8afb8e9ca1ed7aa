// SPDX-License-Identifier: MIT
// The viewer's drawing: one panel's canvas from the model, in the panel's view (geometry.js):
// walls, balls coloured by speed, trails, turtles with their sensor flashes and roles, labels.

import {apply, layerBits, pixelMatrix, transformOf, wallPose} from './geometry.js';
import {BUCKETS, S} from './protocol.js';

export const COLOURS = {
  background: '#f8f8f4', wall: '#222222', it: '#d62828', remote: '#6a4c93',
  heading: '#ffffff', outline: '#222222', flash: 'rgba(255, 160, 0, 0.9)', ray: '#d6336c', miss: 'rgba(214, 51, 108, 0.3)',
};
const FLASH_MS = 400;
// Turtle i's colour, as `render` and `run --svg` draw it (formats/look.hpp: Tableau 10, repeating
// after ten turtles): a turtle looks the same in the viewer, a replay, a picture and a video.
export const TURTLE_COLOURS = ['#4e79a7', '#f28e2b', '#e15759', '#76b7b2', '#59a14f', '#edc948', '#b07aa1', '#ff9da7',
                               '#9c755f', '#bab0ac'];
export const turtleColour = (i) => TURTLE_COLOURS[i % TURTLE_COLOURS.length];
// A body's colour from the world file's "colour" key (the world message's `colours`, by id), if any.
const worldColour = (id) => (S.world && S.world.colours && S.world.colours[id]) || null;

function bucketColour(k) {
  // A blue-green-yellow-red ramp.
  const x = k / (BUCKETS - 1);
  const h = 240 - 240 * x;
  return `hsl(${h.toFixed(0)}, 80%, ${(45 + 5 * Math.sin(Math.PI * x)).toFixed(0)}%)`;
}
export const BUCKET_COLOURS = Array.from({length: BUCKETS}, (_, k) => bucketColour(k));

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

export function drawPanel(p, now) {
  if (!fitCanvas(p)) return;
  const ctx = p.ctx, W = p.canvas.width, H = p.canvas.height, v = p.view;
  const layers = layerBits(v.layers);
  const tf = transformOf(v, S.turtles);
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
      ctx.strokeStyle = worldColour(w.id) || COLOURS.wall;
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
  if (layers & 8) {  // trails, each in its turtle's colour
    ctx.lineWidth = 1.5 * px;
    ctx.lineJoin = 'round';
    for (const [i, t] of S.turtles.entries()) {
      if (!t.trail.length) continue;
      ctx.strokeStyle = turtleColour(i);
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
  if ((layers & 16) && (layers & 4)) drawRays(ctx, px, tf.followed);
  if (layers & 4) {  // turtles
    for (const [i, t] of S.turtles.entries()) {
      if (t.gone) continue;  // crushed, out of the arena or removed: no longer in the world
      if (t.x + t.radius < x0 || t.x - t.radius > x1 || t.y + t.radius < y0 || t.y - t.radius > y1) continue;
      ctx.fillStyle = worldColour(t.id) || turtleColour(i);
      ctx.beginPath();
      ctx.arc(t.x, t.y, t.radius, 0, 2 * Math.PI);
      ctx.fill();
      // The outline: dark; a remote turtle's (driven by a client) thick and purple.
      ctx.strokeStyle = t.remote ? COLOURS.remote : COLOURS.outline;
      ctx.lineWidth = t.remote ? Math.max(2.5 * px, t.radius / 5) : 1 * px;
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
      if (t.gone) continue;
      const [qx, qy] = apply(M, t.x, t.y);
      if (qx < -20 || qx > W + 20 || qy < -20 || qy > H + 20) continue;
      const label = (layers & 32) && t.it ? t.id + ' (it)' : t.id;
      ctx.fillStyle = (layers & 32) && t.it ? COLOURS.it : '#333';
      ctx.fillText(label, qx, qy - (t.radius * M.k + 6 * dpr));
    }
  }
  ctx.setTransform(1, 0, 0, 1, 0, 0);
}

/// Range sensors' last readings (`sense` events): each ray from the turtle's centre to what it hit
/// (a dot there), or faint and dashed to its range when it hit nothing. Drawn while the turtle is
/// at the pose the reading came with, so a ray is never shown from where it was not cast; in a
/// view that follows a turtle, that turtle's rays only.
function drawRays(ctx, px, followed) {
  for (const t of S.turtles) {
    if (t.gone || !t.readings.size || (followed && followed !== t)) continue;
    for (const r of t.readings.values()) {
      if (r.x !== t.x || r.y !== t.y || r.heading !== t.heading) continue;
      r.bearings.forEach((b, k) => {
        const a = (r.heading + b) * Math.PI / 180, d = r.range[k];
        const ux = Math.sin(a), uy = Math.cos(a), len = d === null || d === undefined ? r.max : d;
        const hit = !(d === null || d === undefined);
        ctx.strokeStyle = hit ? COLOURS.ray : COLOURS.miss;
        ctx.lineWidth = 2 * px;
        ctx.setLineDash(hit ? [] : [4 * px, 4 * px]);
        ctx.beginPath();
        ctx.moveTo(r.x, r.y);
        ctx.lineTo(r.x + len * ux, r.y + len * uy);
        ctx.stroke();
        if (hit) {
          ctx.fillStyle = COLOURS.ray;
          ctx.beginPath();
          ctx.arc(r.x + len * ux, r.y + len * uy, 3.5 * px, 0, 2 * Math.PI);
          ctx.fill();
        }
      });
    }
  }
  ctx.setLineDash([]);
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
  // Balls with a colour of their own in the world file: drawn over their speed's colour in it.
  const colours = S.world && S.world.colours;
  if (!colours) return;
  for (let i = 0; i < b.n; i++) {
    const c = colours[b.ids[i]];
    if (!c) continue;
    const x = pos[2 * i], y = pos[2 * i + 1], r = Math.max(rad[i], 0.75 * px);
    if (!(x + r >= x0 && x - r <= x1 && y + r >= y0 && y - r <= y1)) continue;
    ctx.fillStyle = c;
    ctx.beginPath();
    ctx.arc(x, y, r, 0, 2 * Math.PI);
    ctx.fill();
  }
}

