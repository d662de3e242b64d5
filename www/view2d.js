// Fallback view for browsers without WebGL, on a 2D canvas: shaded surface triangles
// (painter's algorithm), patch colours or the heat map, the rest area a plan leaves (by
// reason, sorted with the surface, and a ring at each region), a space-filling curve's cells
// and tree and the watershed rectangles (projected like everything else, drawn over the
// surface), extraordinary points,
// control mesh, the path by kind and the tool as its outline. Same interface as View3D. Z is
// up; mm.
import {
  BACKGROUND, CAGE_COLOUR, EP_COLOUR, ISFC_LAYER, KINDS, PATCH_COLOURS, RECT_LAYER, REST_REASONS, STOCK, VIEWS, GRID, ZERO_TRIAD, boxEdges, heatColour, hexCss, pathColour, tableGrid,
} from './colours.js';

const rgb = (c) => [c >> 16 & 255, c >> 8 & 255, c & 255];

export class View2D {
  constructor(canvas) {
    this.kind = '2d';
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.yaw = -0.5;
    this.pitch = 0.7;
    this.zoom = 1;
    this.pan = [0, 0];
    this.model = null;
    this.path = null;
    this.tool = null;
    this.heat = null;
    this.rest = null;
    this.isfc = null;
    this.center = [0, 0, 0];
    this.radius = 1;
    this.layers = { surface: true, rest: true, isfc: false, rects: false, path: true, tool: true, cage: false, eps: true, zero: true, grid: true };
    /** The drawing is always a parallel projection. */
    this.ortho = true;
    this.#bindInput();
    this.resizer = new ResizeObserver(() => this.resize());
    this.resizer.observe(canvas);
    this.resize();
  }

  resize() {
    const dpr = Math.min(2, window.devicePixelRatio || 1);
    this.canvas.width = Math.max(1, Math.round(this.canvas.clientWidth * dpr));
    this.canvas.height = Math.max(1, Math.round(this.canvas.clientHeight * dpr));
    // Setting the size cleared the canvas: draw again at once, not a frame later.
    this.renderNow();
  }

  setModel(m) {
    this.model = m;
    this.heat = null;
    this.path = null;
    this.tool = null;
    this.rest = null;
    this.isfc = null;
    this.fit();
  }

  setHeat(values, scallopMm) {
    this.heat = values ? { values, scallopMm } : null;
    this.render();
  }

  /** The rest area (see View3D.setRest) or null. */
  setRest(rest) {
    this.rest = rest && (rest.positions.length || rest.regions?.length) ? rest : null;
    this.render();
  }

  /** A space-filling curve's cells and tree (see View3D.setIsfc) or null. */
  setIsfc(isfc) {
    this.isfc = isfc && isfc.cells.length ? isfc : null;
    this.render();
  }

  /** The watershed rectangles (see View3D.setRects) or null. */
  setRects(rects) {
    this.rects = rects && rects.fills.length ? rects : null;
    this.render();
  }

  setPath(path) {
    this.path = path;
    this.render();
  }

  setTool(t) {
    this.tool = t;
    this.render();
  }

  setLayers(layers) {
    Object.assign(this.layers, layers);
    this.render();
  }

  /** Centres the model and frames it; from the standard view `name` (VIEWS) if given. */
  fit(name = null) {
    if (!this.model) return;
    if (VIEWS[name]) {
      const d = VIEWS[name];
      const n = Math.hypot(...d);
      this.pitch = Math.max(-1.55, Math.min(1.55, Math.asin(d[2] / n)));
      if (Math.hypot(d[0], d[1]) > 1e-3 * n) this.yaw = Math.atan2(-d[0], -d[1]);
      else this.yaw = 0;
    }
    const p = this.model.positions;
    const lo = [Infinity, Infinity, Infinity];
    const hi = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < p.length; i += 3) {
      for (let k = 0; k < 3; k++) {
        lo[k] = Math.min(lo[k], p[i + k]);
        hi[k] = Math.max(hi[k], p[i + k]);
      }
    }
    this.center = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
    this.radius = Math.max(1e-6, Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) / 2);
    this.zoom = 1;
    this.pan = [0, 0];
    this.render();
  }

  /** Frames a sphere of `radius` (mm) round `centre`, seen from direction `from` (a unit
   * vector from the centre towards the viewer; the current direction if null). */
  focus(centre, radius, from = null) {
    if (from) {
      this.pitch = Math.max(-1.55, Math.min(1.55, Math.asin(Math.max(-1, Math.min(1, from[2])))));
      if (Math.hypot(from[0], from[1]) > 1e-9) this.yaw = Math.atan2(-from[0], -from[1]);
    }
    this.zoom = Math.max(1, this.radius / Math.max(radius, 1e-9));
    this.pan = [0, 0];
    const q = this.#project()(...centre);
    this.pan = [this.canvas.width / 2 - q[0], this.canvas.height / 2 - q[1]];
    this.render();
  }

  /** The radius of the model's bounding sphere (mm). */
  get modelRadius() {
    return this.radius;
  }

  /** The 2D drawing is always orthographic (parallel). */
  setOrtho() {}

  #project() {
    const { width, height } = this.canvas;
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    const scale = (0.45 * Math.min(width, height) * this.zoom) / this.radius;
    const [cx0, cy0, cz0] = this.center;
    const proj = (x, y, z) => {
      const dx = x - cx0, dy = y - cy0, dz = z - cz0;
      const rx = cy * dx - sy * dy;
      const ry = sy * dx + cy * dy;
      const up = sp * ry + cp * dz;
      const depth = cp * ry - sp * dz; // larger is farther from the viewer
      return [width / 2 + this.pan[0] + rx * scale, height / 2 + this.pan[1] - up * scale, depth];
    };
    proj.scale = scale;
    return proj;
  }

  #viewDir() {
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    return [-sy * cp, -cy * cp, sp];
  }

  render() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.renderNow();
    });
  }

  renderNow() {
    const ctx = this.ctx;
    const { width, height } = this.canvas;
    ctx.fillStyle = hexCss(BACKGROUND);
    ctx.fillRect(0, 0, width, height);
    if (!this.model) return;
    const proj = this.#project();
    const overlays = this.#overlays();
    if (this.layers.grid) this.#drawGrid(proj);
    if (this.layers.surface || overlays.length) this.#drawSurface(proj, overlays);
    if (this.layers.rest && this.rest) this.#drawRestRings(proj);
    if (this.layers.isfc && this.isfc) this.#drawIsfc(proj);
    if (this.layers.rects && this.rects) this.#drawRects(proj);
    if (this.layers.cage) this.#drawCage(proj);
    if (this.layers.zero) this.#drawZero(proj);
    if (this.layers.eps) this.#drawEps(proj);
    if (this.layers.path && this.path) this.#drawPath(proj);
    if (this.layers.tool && this.tool) this.#drawTool(proj);
  }

  /** Triangles drawn over the surface, sorted with it: the rest area (by reason) and the
   * watershed rectangles (by region kind), each `{ positions, colour(t), alpha }`. */
  #overlays() {
    const out = [];
    if (this.layers.rest && this.rest) {
      const why = this.rest.reasons;
      out.push({ positions: this.rest.positions, alpha: 0.85, colour: (t) => (REST_REASONS[why[t]] || REST_REASONS[0]).colour });
    }
    if (this.layers.rects && this.rects) {
      const kinds = this.rects.kinds;
      out.push({ positions: this.rects.fills, alpha: 0.8, colour: (t) => (RECT_LAYER.kinds[kinds[t]] || RECT_LAYER.kinds[0]).colour });
    }
    return out;
  }

  /** Surface triangles and the overlays' triangles, sorted together by depth (an overlay
   * triangle a little nearer than the surface it lies on). */
  #drawSurface(proj, overlays) {
    const ctx = this.ctx;
    const { positions: p, normals: n, indices: idx, patchIds } = this.model;
    const nv = p.length / 3;
    const sx = new Float32Array(nv), sy = new Float32Array(nv), sd = new Float32Array(nv);
    for (let i = 0; i < nv; i++) {
      const q = proj(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      sx[i] = q[0]; sy[i] = q[1]; sd[i] = q[2];
    }
    const nt = this.layers.surface ? idx.length / 3 : 0;
    // Overlay triangle r is triangle r - first[o] of overlay o.
    const first = [];
    let nr = 0;
    for (const o of overlays) {
      first.push(nr);
      nr += o.positions.length / 9;
    }
    const rx = new Float32Array(3 * nr), ry = new Float32Array(3 * nr), rd = new Float32Array(3 * nr);
    overlays.forEach((o, k) => {
      const rp = o.positions;
      for (let i = 0; i < rp.length / 3; i++) {
        const q = proj(rp[3 * i], rp[3 * i + 1], rp[3 * i + 2]);
        const j = 3 * first[k] + i;
        rx[j] = q[0]; ry[j] = q[1]; rd[j] = q[2];
      }
    });
    const which = new Uint8Array(nr);
    overlays.forEach((o, k) => which.fill(k, first[k], first[k] + o.positions.length / 9));
    const order = new Uint32Array(nt + nr);
    const depth = new Float32Array(nt + nr);
    for (let t = 0; t < nt; t++) {
      order[t] = t;
      depth[t] = sd[idx[3 * t]] + sd[idx[3 * t + 1]] + sd[idx[3 * t + 2]];
    }
    const bias = 3e-3 * this.radius;
    for (let t = 0; t < nr; t++) {
      order[nt + t] = nt + t;
      depth[nt + t] = rd[3 * t] + rd[3 * t + 1] + rd[3 * t + 2] - bias;
    }
    order.sort((a, b) => depth[b] - depth[a]);
    const v = this.#viewDir();
    const light = normalize([v[0] + 0.3, v[1] - 0.2, v[2] + 0.6]);
    for (const t of order) {
      if (t >= nt) {
        const r = t - nt;
        const o = overlays[which[r]];
        ctx.fillStyle = hexCss(o.colour(r - first[which[r]]));
        ctx.globalAlpha = o.alpha;
        ctx.beginPath();
        ctx.moveTo(rx[3 * r], ry[3 * r]);
        ctx.lineTo(rx[3 * r + 1], ry[3 * r + 1]);
        ctx.lineTo(rx[3 * r + 2], ry[3 * r + 2]);
        ctx.closePath();
        ctx.fill();
        ctx.globalAlpha = 1;
        continue;
      }
      const a = idx[3 * t], b = idx[3 * t + 1], c = idx[3 * t + 2];
      const nrm = normalize([
        n[3 * a] + n[3 * b] + n[3 * c],
        n[3 * a + 1] + n[3 * b + 1] + n[3 * c + 1],
        n[3 * a + 2] + n[3 * b + 2] + n[3 * c + 2],
      ]);
      const facing = nrm[0] * v[0] + nrm[1] * v[1] + nrm[2] * v[2] >= 0 ? 1 : -1;
      const lambert = Math.max(0, facing * (nrm[0] * light[0] + nrm[1] * light[1] + nrm[2] * light[2]));
      const k = 0.4 + 0.6 * lambert;
      let base;
      if (this.heat) {
        // The worst of the three corners.
        const h = this.heat.values;
        const w = [h[a], h[b], h[c]].reduce((m, x) => (!Number.isFinite(x) || x < 0 || x > m ? x : m), 0);
        base = rgb(heatColour(w, this.heat.scallopMm));
      } else {
        base = rgb(PATCH_COLOURS[patchIds[t] % PATCH_COLOURS.length]);
      }
      ctx.fillStyle = `rgb(${(base[0] * k) | 0},${(base[1] * k) | 0},${(base[2] * k) | 0})`;
      ctx.beginPath();
      ctx.moveTo(sx[a], sy[a]);
      ctx.lineTo(sx[b], sy[b]);
      ctx.lineTo(sx[c], sy[c]);
      ctx.closePath();
      ctx.fill();
      ctx.strokeStyle = ctx.fillStyle;
      ctx.lineWidth = 0.5;
      ctx.stroke();
    }
  }

  /** A ring at each rest region, so that small ones are seen. */
  #drawRestRings(proj) {
    const ctx = this.ctx;
    ctx.lineWidth = 2.5;
    for (const r of this.rest.regions || []) {
      const a = proj(...r.centre_mm);
      ctx.strokeStyle = hexCss((REST_REASONS.find((x) => x.why === r.why) || REST_REASONS[0]).colour);
      ctx.beginPath();
      ctx.arc(a[0], a[1], 7, 0, 2 * Math.PI);
      ctx.stroke();
    }
  }

  /** Line segments (`x y z x y z` each) for which `which(s)` holds, in one colour. */
  #segments(proj, a, which, colour, width, alpha) {
    const ctx = this.ctx;
    ctx.strokeStyle = hexCss(colour);
    ctx.lineWidth = width;
    ctx.globalAlpha = alpha;
    ctx.beginPath();
    for (let i = 0, s = 0; i < a.length; i += 6, s++) {
      if (!which(s)) continue;
      const p = proj(a[i], a[i + 1], a[i + 2]);
      const q = proj(a[i + 3], a[i + 4], a[i + 5]);
      ctx.moveTo(p[0], p[1]);
      ctx.lineTo(q[0], q[1]);
    }
    ctx.stroke();
    ctx.globalAlpha = 1;
  }

  /** Cell outlines, then the tree's links (those across a patch side in their own colour). */
  #drawIsfc(proj) {
    const { cells, tree, across } = this.isfc;
    this.#segments(proj, cells, () => true, ISFC_LAYER.cell, 0.75, 0.7);
    this.#segments(proj, tree, (s) => !across[s], ISFC_LAYER.tree, 1.25, 1);
    this.#segments(proj, tree, (s) => across[s], ISFC_LAYER.across, 1.5, 1);
  }

  /** The rectangles' outlines and arrows (their fills are sorted with the surface). */
  #drawRects(proj) {
    this.#segments(proj, this.rects.outlines, () => true, RECT_LAYER.outline, 1, 0.9);
    this.#segments(proj, this.rects.arrows, () => true, RECT_LAYER.arrow, 1.5, 1);
  }

  /** The table grid (see View3D). */
  #drawGrid(proj) {
    const grid = tableGrid(this.model.summary?.stock_mm || this.model.summary?.bbox_mm);
    if (grid) this.#segments(proj, grid.lines, () => true, GRID.line, 1, 0.7);
  }

  /** Program zero: the axis triad at the model's origin (see View3D). */
  #drawZero(proj) {
    const stock = this.model.summary?.stock_mm;
    if (stock) this.#segments(proj, boxEdges(stock), () => true, STOCK.edge, 1, 0.8);
    const len = 0.4 * this.radius;
    const axes = [[len, 0, 0], [0, len, 0], [0, 0, len]];
    axes.forEach((a, k) => this.#segments(proj, [0, 0, 0, ...a], () => true, ZERO_TRIAD[k], 2, 1));
  }

  #drawCage(proj) {
    const ctx = this.ctx;
    const e = this.model.cage;
    ctx.strokeStyle = hexCss(CAGE_COLOUR);
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let i = 0; i < e.length; i += 6) {
      const a = proj(e[i], e[i + 1], e[i + 2]);
      const b = proj(e[i + 3], e[i + 4], e[i + 5]);
      ctx.moveTo(a[0], a[1]);
      ctx.lineTo(b[0], b[1]);
    }
    ctx.stroke();
  }

  #drawEps(proj) {
    const ctx = this.ctx;
    const e = this.model.eps;
    ctx.fillStyle = hexCss(EP_COLOUR);
    ctx.strokeStyle = '#000';
    for (let i = 0; i < e.length; i += 3) {
      const a = proj(e[i], e[i + 1], e[i + 2]);
      ctx.beginPath();
      ctx.arc(a[0], a[1], 5, 0, 2 * Math.PI);
      ctx.fill();
      ctx.stroke();
    }
  }

  #drawPath(proj) {
    const ctx = this.ctx;
    const { cl, kinds, patchIds } = this.path;
    const n = kinds.length;
    ctx.lineWidth = 1;
    let current = null;
    for (let i = 1; i < n; i++) {
      const kind = KINDS[kinds[i]] || KINDS[0];
      const style = hexCss(kind.colour === null ? pathColour(patchIds[i]) : kind.colour);
      const tag = style + kind.dashed;
      if (current !== tag) {
        if (current !== null) ctx.stroke();
        ctx.strokeStyle = style;
        ctx.setLineDash(kind.dashed ? [4, 4] : []);
        ctx.beginPath();
        const a = proj(cl[3 * i - 3], cl[3 * i - 2], cl[3 * i - 1]);
        ctx.moveTo(a[0], a[1]);
        current = tag;
      }
      const b = proj(cl[3 * i], cl[3 * i + 1], cl[3 * i + 2]);
      ctx.lineTo(b[0], b[1]);
    }
    if (current !== null) ctx.stroke();
    ctx.setLineDash([]);
  }

  #drawTool(proj) {
    const ctx = this.ctx;
    const t = this.tool;
    const c = proj(...t.centre);
    const at = (d) => proj(t.centre[0] + t.axis[0] * d, t.centre[1] + t.axis[1] * d, t.centre[2] + t.axis[2] * d);
    const top = at(t.shankLength);
    const holder = at(t.shankLength + t.holderLength);
    ctx.lineCap = 'round';
    ctx.strokeStyle = 'rgba(74,85,104,0.35)';
    ctx.lineWidth = Math.max(2, 2 * t.holderRadius * proj.scale);
    ctx.beginPath(); ctx.moveTo(top[0], top[1]); ctx.lineTo(holder[0], holder[1]); ctx.stroke();
    ctx.strokeStyle = '#8a93a3';
    ctx.lineWidth = Math.max(2, 2 * t.shankRadius * proj.scale);
    ctx.beginPath(); ctx.moveTo(c[0], c[1]); ctx.lineTo(top[0], top[1]); ctx.stroke();
    ctx.fillStyle = '#8a93a3';
    ctx.beginPath(); ctx.arc(c[0], c[1], Math.max(2, t.radius * proj.scale), 0, 2 * Math.PI); ctx.fill();
    ctx.lineCap = 'butt';
  }

  /** Renders now and returns the frame's pixels, RGBA rows. */
  snapshot() {
    this.renderNow();
    return new Uint8Array(this.ctx.getImageData(0, 0, this.canvas.width, this.canvas.height).data.buffer);
  }

  countPixels() {
    const { width, height } = this.canvas;
    const d = this.snapshot();
    const bg = rgb(BACKGROUND);
    let drawn = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]) > 24) drawn++;
    }
    return { drawn, total: width * height };
  }

  #bindInput() {
    const c = this.canvas;
    let drag = null;
    c.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 };
      c.setPointerCapture(e.pointerId);
    });
    c.addEventListener('pointermove', (e) => {
      if (!drag) return;
      const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
      drag.x = e.clientX; drag.y = e.clientY;
      if (drag.pan) {
        const s = c.width / c.clientWidth;
        this.pan = [this.pan[0] + dx * s, this.pan[1] + dy * s];
      } else {
        this.yaw += dx * 0.01;
        this.pitch = Math.max(-1.55, Math.min(1.55, this.pitch + dy * 0.01));
      }
      this.render();
    });
    c.addEventListener('pointerup', () => { drag = null; });
    c.addEventListener('contextmenu', (e) => e.preventDefault());
    c.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.zoom *= Math.exp(-e.deltaY * 0.001);
      this.render();
    }, { passive: false });
    c.addEventListener('keydown', (e) => {
      const step = 0.1;
      if (e.key === 'ArrowLeft') { if (e.shiftKey) this.pan[0] -= 20; else this.yaw -= step; }
      else if (e.key === 'ArrowRight') { if (e.shiftKey) this.pan[0] += 20; else this.yaw += step; }
      else if (e.key === 'ArrowUp') { if (e.shiftKey) this.pan[1] -= 20; else this.pitch = Math.min(1.55, this.pitch + step); }
      else if (e.key === 'ArrowDown') { if (e.shiftKey) this.pan[1] += 20; else this.pitch = Math.max(-1.55, this.pitch - step); }
      else if (e.key === '+' || e.key === '=') this.zoom *= 1.15;
      else if (e.key === '-' || e.key === '_') this.zoom /= 1.15;
      else if (e.key === 'f' || e.key === 'F') { this.fit(); e.preventDefault(); return; }
      else return;
      e.preventDefault();
      this.render();
    });
  }

  dispose() {
    this.resizer.disconnect();
  }
}

function normalize(v) {
  const l = Math.hypot(v[0], v[1], v[2]) || 1;
  return [v[0] / l, v[1] / l, v[2] / l];
}
