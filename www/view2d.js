// Fallback view for browsers without WebGL, on a 2D canvas: shaded surface triangles
// (painter's algorithm), patch colours or the heat map, extraordinary points, control mesh,
// the path by kind and the tool as its outline. Same interface as View3D. Z is up; mm.
import {
  BACKGROUND, CAGE_COLOUR, EP_COLOUR, KINDS, PATCH_COLOURS, heatColour, hexCss, pathColour,
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
    this.center = [0, 0, 0];
    this.radius = 1;
    this.layers = { surface: true, path: true, tool: true, cage: false, eps: true };
    this.#bindInput();
    this.resizer = new ResizeObserver(() => this.resize());
    this.resizer.observe(canvas);
    this.resize();
  }

  resize() {
    const dpr = Math.min(2, window.devicePixelRatio || 1);
    this.canvas.width = Math.max(1, Math.round(this.canvas.clientWidth * dpr));
    this.canvas.height = Math.max(1, Math.round(this.canvas.clientHeight * dpr));
    this.render();
  }

  setModel(m) {
    this.model = m;
    this.heat = null;
    this.path = null;
    this.tool = null;
    this.fit();
  }

  setHeat(values, scallopMm) {
    this.heat = values ? { values, scallopMm } : null;
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

  fit() {
    if (!this.model) return;
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
    if (this.layers.surface) this.#drawSurface(proj);
    if (this.layers.cage) this.#drawCage(proj);
    if (this.layers.eps) this.#drawEps(proj);
    if (this.layers.path && this.path) this.#drawPath(proj);
    if (this.layers.tool && this.tool) this.#drawTool(proj);
  }

  #drawSurface(proj) {
    const ctx = this.ctx;
    const { positions: p, normals: n, indices: idx, patchIds } = this.model;
    const nv = p.length / 3;
    const sx = new Float32Array(nv), sy = new Float32Array(nv), sd = new Float32Array(nv);
    for (let i = 0; i < nv; i++) {
      const q = proj(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
      sx[i] = q[0]; sy[i] = q[1]; sd[i] = q[2];
    }
    const nt = idx.length / 3;
    const order = new Uint32Array(nt);
    const depth = new Float32Array(nt);
    for (let t = 0; t < nt; t++) {
      order[t] = t;
      depth[t] = sd[idx[3 * t]] + sd[idx[3 * t + 1]] + sd[idx[3 * t + 2]];
    }
    order.sort((a, b) => depth[b] - depth[a]);
    const v = this.#viewDir();
    const light = normalize([v[0] + 0.3, v[1] - 0.2, v[2] + 0.6]);
    for (const t of order) {
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
