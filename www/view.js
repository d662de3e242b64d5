// Orbit view on a 2D canvas: shaded surface triangles (painter's algorithm) and the tool
// path as polylines. Z is up; lengths are millimetres.

const PATCH_COLOURS = [
  [120, 160, 220], [230, 160, 90], [120, 190, 130], [210, 120, 140],
  [170, 140, 210], [200, 190, 100], [110, 190, 190], [190, 150, 120],
];
const PATH_COLOURS = ['#0b3d91', '#8a2be2', '#006400', '#8b0000', '#b8860b', '#008b8b'];

export class View {
  constructor(canvas) {
    this.canvas = canvas;
    this.ctx = canvas.getContext('2d');
    this.yaw = -0.6;
    this.pitch = 0.6;
    this.zoom = 1;
    this.pan = [0, 0];
    this.mesh = null;
    this.path = null;
    this.center = [0, 0, 0];
    this.radius = 1;
    this.#bindInput();
  }

  /** Surface triangles: Float32Array positions/normals, Uint32Array indices and patch ids. */
  setMesh(positions, normals, indices, patchIds) {
    this.mesh = { positions, normals, indices, patchIds };
    this.fit();
  }

  /** Tool path: Float64Array CL points (x y z per move), Uint8Array kinds, Uint32Array patches. */
  setPath(points, kinds, patchIds) {
    this.path = points ? { points, kinds, patchIds } : null;
    this.render();
  }

  /** Centres the model and zooms so it fills the view. */
  fit() {
    if (!this.mesh) return;
    const p = this.mesh.positions;
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
    // Camera: rotate about Z by yaw, then tilt about the screen's x axis by pitch.
    return (x, y, z) => {
      const dx = x - cx0, dy = y - cy0, dz = z - cz0;
      const rx = cy * dx - sy * dy;
      const ry = sy * dx + cy * dy;
      const sx = rx;
      const syy = sp * ry + cp * dz; // screen up
      const depth = cp * ry - sp * dz; // larger is farther from the viewer
      return [width / 2 + this.pan[0] + sx * scale, height / 2 + this.pan[1] - syy * scale, depth];
    };
  }

  #viewDir() {
    // Direction from the scene towards the viewer, in model coordinates.
    const cy = Math.cos(this.yaw), sy = Math.sin(this.yaw);
    const cp = Math.cos(this.pitch), sp = Math.sin(this.pitch);
    // The viewer sits at (0, -cos pitch, sin pitch) in the yaw-rotated frame.
    return [-sy * cp, -cy * cp, sp];
  }

  render() {
    const ctx = this.ctx;
    const { width, height } = this.canvas;
    ctx.fillStyle = '#eef1f5';
    ctx.fillRect(0, 0, width, height);
    if (!this.mesh) return;
    const proj = this.#project();
    const { positions: p, normals: n, indices: idx, patchIds } = this.mesh;
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
      let nx = n[3 * a] + n[3 * b] + n[3 * c];
      let ny = n[3 * a + 1] + n[3 * b + 1] + n[3 * c + 1];
      let nz = n[3 * a + 2] + n[3 * b + 2] + n[3 * c + 2];
      const len = Math.hypot(nx, ny, nz) || 1;
      nx /= len; ny /= len; nz /= len;
      // Two-sided lighting: the back of a sheet is lit like its front.
      const facing = nx * v[0] + ny * v[1] + nz * v[2] >= 0 ? 1 : -1;
      const lambert = Math.max(0, facing * (nx * light[0] + ny * light[1] + nz * light[2]));
      const k = 0.35 + 0.65 * lambert;
      const base = PATCH_COLOURS[patchIds[t] % PATCH_COLOURS.length];
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
    if (this.path) this.#drawPath(proj);
  }

  #drawPath(proj) {
    const ctx = this.ctx;
    const { points, kinds, patchIds } = this.path;
    const n = points.length / 3;
    ctx.lineWidth = 1;
    let current = null;
    for (let i = 1; i < n; i++) {
      const kind = kinds[i];
      const style = kind === 2 || kind === 3 ? '#d62728' : PATH_COLOURS[patchIds[i] % PATH_COLOURS.length];
      const dash = kind === 2 || kind === 3 ? [4, 4] : [];
      if (current !== style + dash.length) {
        if (current !== null) ctx.stroke();
        ctx.strokeStyle = style;
        ctx.setLineDash(dash);
        ctx.beginPath();
        const a = proj(points[3 * i - 3], points[3 * i - 2], points[3 * i - 1]);
        ctx.moveTo(a[0], a[1]);
        current = style + dash.length;
      }
      const b = proj(points[3 * i], points[3 * i + 1], points[3 * i + 2]);
      ctx.lineTo(b[0], b[1]);
    }
    if (current !== null) ctx.stroke();
    ctx.setLineDash([]);
  }

  #bindInput() {
    const c = this.canvas;
    let drag = null;
    c.addEventListener('pointerdown', (e) => {
      drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey };
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
    c.addEventListener('wheel', (e) => {
      e.preventDefault();
      this.zoom *= Math.exp(-e.deltaY * 0.001);
      this.render();
    }, { passive: false });
    c.addEventListener('keydown', (e) => {
      const step = 0.1;
      if (e.key === 'ArrowLeft') this.yaw -= step;
      else if (e.key === 'ArrowRight') this.yaw += step;
      else if (e.key === 'ArrowUp') this.pitch = Math.min(1.55, this.pitch + step);
      else if (e.key === 'ArrowDown') this.pitch = Math.max(-1.55, this.pitch - step);
      else if (e.key === '+' || e.key === '=') this.zoom *= 1.1;
      else if (e.key === '-') this.zoom /= 1.1;
      else if (e.key === 'f' || e.key === 'F') { this.fit(); return; }
      else return;
      e.preventDefault();
      this.render();
    });
  }
}

function normalize(v) {
  const l = Math.hypot(v[0], v[1], v[2]) || 1;
  return [v[0] / l, v[1] / l, v[2] / l];
}
