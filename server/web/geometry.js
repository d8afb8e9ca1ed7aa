// SPDX-License-Identifier: MIT
// The viewer's geometry, that of turtle/view.hpp: a view shows [-w/2, w/2] x [-h/2, h/2] around
// its centre in view coordinates (x right, y up); a fixed view's centre is `center`, a follow
// view's the followed turtle plus `offset` (in its frame, and turned with it, when `rotate`). Each
// view's canvas has the view's aspect ratio, so world point p lands on canvas pixel
//   ((v.x / w + 0.5) * canvas.width, (0.5 - v.y / h) * canvas.height),   v = p in view coordinates.
// Pure functions: nothing here reads the page or the model.

export const LAYERS = ['walls', 'balls', 'turtles', 'trails', 'sensors', 'roles'];
export const ALL_LAYERS = (1 << LAYERS.length) - 1;

export function layerBits(names) {
  if (names === 'all' || names === undefined) return ALL_LAYERS;
  let bits = 0;
  for (const n of names) { const k = LAYERS.indexOf(n); if (k >= 0) bits |= 1 << k; }
  return bits;
}


/// The view's centre, axes (right, up: unit vectors in world coordinates) and size, for the
/// turtles as they are now (a follow view's turtle is looked up among them).
export function transformOf(view, turtles) {
  const size = view.size || [200, 200];
  let center = view.center || [0, 0], right = [1, 0], up = [0, 1];
  const t = view.follow ? turtles.find((x) => x.id === view.follow) : null;
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

export function pixelMatrix(tf, W, H) {
  const kx = W / tf.size[0], ky = H / tf.size[1];
  const [cx, cy] = tf.center, [rx, ry] = tf.right, [ux, uy] = tf.up;
  return {a: kx * rx, b: -ky * ux, c: kx * ry, d: -ky * uy,
          e: W / 2 - kx * (cx * rx + cy * ry), f: H / 2 + ky * (cx * ux + cy * uy), k: kx};
}
export const apply = (M, x, y) => [M.a * x + M.c * y + M.e, M.b * x + M.d * y + M.f];
export function invert(M, px, py) {
  const det = M.a * M.d - M.b * M.c;
  const x = px - M.e, y = py - M.f;
  return [(M.d * x - M.c * y) / det, (-M.b * x + M.a * y) / det];
}

/// A wall's ends at time t (its keys) and whether it is there (its visibility).
export function wallPose(w, t) {
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

