// The 3D view with three.js (vendored in www/vendor/): shaded surface with patches in
// colours (or the scallop heat map), extraordinary points, optional control mesh, the rest
// area a plan leaves (coloured by reason, with a ring at each region), a space-filling
// curve's cells and tree and the watershed rectangles (off until shown), the tool path by
// patch with links and retractions drawn apart, and the tool (ball, shank, holder).
// Z is up; lengths are millimetres. Renders on demand, not in a loop.
import * as THREE from './vendor/three-view.js';
import { OrbitControls } from './vendor/three-view.js';
import {
  BACKGROUND, CAGE_COLOUR, EP_COLOUR, GRID, ISFC_LAYER, KINDS, PATCH_COLOURS, RECT_LAYER, REST_REASONS, STOCK, VIEWS, ZERO_TRIAD, boxEdges, heatColour, pathColour, tableGrid,
} from './colours.js';

const ORBIT_STEP_RAD = Math.PI / 36; // arrow keys: 5°
const FOV_DEG = 35;

/** The model surface's material: per-corner colours (patches or heat), both sides lit. */
function surfaceMaterial() {
  return new THREE.MeshPhongMaterial({
    vertexColors: true, side: THREE.DoubleSide, shininess: 25,
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
}

/** The stock block's translucent faces. */
function stockMaterial() {
  return new THREE.MeshBasicMaterial({ color: STOCK.face, transparent: true, opacity: STOCK.opacity, depthWrite: false, side: THREE.DoubleSide });
}

/** The name of the renderer WebGL draws with here (as the driver says it), from a small
 * context of its own that is let go at once; '' if unknown. */
function rendererName() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    if (!gl) return '';
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : '';
    gl.getExtension('WEBGL_lose_context')?.loseContext();
    return name;
  } catch {
    return '';
  }
}

/** Whether a renderer name is of a CPU rasteriser (no graphics hardware, as in a virtual
 * machine or headless Chromium). */
const isSoftware = (name) => /swiftshader|llvmpipe|softpipe|software/i.test(name);

export class View3D {
  constructor(canvas) {
    this.kind = 'webgl';
    this.canvas = canvas;
    // Drawn on the CPU, multisampling adds to the work of every frame (the keycap's path:
    // 187 ms of the GPU process with it, 112 ms without, the page held meanwhile), so there
    // edges are left unsmoothed.
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: !isSoftware(rendererName()) });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.renderer.setClearColor(BACKGROUND, 1);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(FOV_DEG, 1, 0.1, 1000);
    this.camera.up.set(0, 0, 1);
    this.scene.add(this.camera);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x707880, 1.6));
    const key = new THREE.DirectionalLight(0xffffff, 1.6);
    key.position.set(0.4, 0.6, 1);
    this.camera.add(key); // the light follows the viewer
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.screenSpacePanning = true;
    this.controls.addEventListener('change', () => this.render());
    this.layers = { surface: true, rest: true, isfc: false, rects: false, path: true, tool: true, cage: false, eps: true, zero: true, grid: true };
    this.groups = {};
    this.ortho = false;
    for (const k of Object.keys(this.layers)) {
      this.groups[k] = new THREE.Group();
      this.scene.add(this.groups[k]);
    }
    this.heat = null;
    this.model = null;
    this.#bindKeys();
    this.resizer = new ResizeObserver(() => this.resize());
    this.resizer.observe(canvas);
    this.resize();
  }

  resize() {
    const w = Math.max(1, this.canvas.clientWidth);
    const h = Math.max(1, this.canvas.clientHeight);
    this.renderer.setSize(w, h, false);
    if (this.camera.isOrthographicCamera) {
      const half = (this.camera.top - this.camera.bottom) / 2;
      this.#orthoFrustum(half);
    } else {
      this.camera.aspect = w / h;
    }
    this.camera.updateProjectionMatrix();
    this.render();
  }

  /** Draws on the next frame (coalesced). */
  render() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.renderNow();
    });
  }

  /** Compiles the shader programs the first drawing of a model needs (the surface, its lines
   * and the stock's faces), while the page waits for the model. The materials stay referenced
   * so three.js keeps their programs for the model's own materials, which share their keys. */
  warmUp() {
    const tri = new THREE.BufferGeometry();
    const one = () => new THREE.BufferAttribute(new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]), 3);
    tri.setAttribute('position', one());
    tri.setAttribute('normal', one());
    tri.setAttribute('color', one());
    const scene = new THREE.Scene();
    scene.add(
      new THREE.Mesh(tri, surfaceMaterial()),
      new THREE.Mesh(tri, stockMaterial()),
      new THREE.LineSegments(tri, new THREE.LineBasicMaterial({ vertexColors: true, depthTest: false })),
      new THREE.LineSegments(tri, new THREE.LineBasicMaterial({ color: STOCK.edge })),
    );
    this.renderer.compile(scene, this.camera, this.scene);
    this.warm = scene;
  }

  renderNow() {
    for (const [k, on] of Object.entries(this.layers)) this.groups[k].visible = on;
    this.renderer.render(this.scene, this.camera);
  }

  #clear(group) {
    for (const o of [...group.children]) {
      group.remove(o);
      o.traverse((x) => {
        if (x.geometry) x.geometry.dispose();
        if (x.material) x.material.dispose();
      });
    }
  }

  /** The surface: `positions`/`normals` (Float32Array, xyz per vertex), `indices`
   * (Uint32Array, 3 per triangle), `patchIds` (per triangle), `eps` (Float64Array xyz per
   * extraordinary point), `cage` (Float64Array, xyz xyz per control-mesh edge). */
  setModel(m) {
    this.model = m;
    this.heat = null;
    for (const g of Object.values(this.groups)) this.#clear(g);
    const { positions: p, normals: n, indices: idx, patchIds } = m;
    // Unshared corners, so each triangle takes its patch's colour.
    const nc = idx.length;
    const pos = new Float32Array(3 * nc);
    const nor = new Float32Array(3 * nc);
    for (let c = 0; c < nc; c++) {
      const v = idx[c];
      for (let k = 0; k < 3; k++) {
        pos[3 * c + k] = p[3 * v + k];
        nor[3 * c + k] = n[3 * v + k];
      }
    }
    const geom = new THREE.BufferGeometry();
    geom.setAttribute('position', new THREE.BufferAttribute(pos, 3));
    geom.setAttribute('normal', new THREE.BufferAttribute(nor, 3));
    geom.setAttribute('color', new THREE.BufferAttribute(new Float32Array(3 * nc), 3));
    geom.computeBoundingSphere();
    this.surface = new THREE.Mesh(geom, surfaceMaterial());
    this.groups.surface.add(this.surface);
    this.#colourSurface();

    const size = geom.boundingSphere.radius;
    this.sceneRadius = size;
    const nep = m.eps.length / 3;
    if (nep > 0) {
      const ball = new THREE.SphereGeometry(Math.max(size * 0.012, 1e-3), 16, 12);
      const inst = new THREE.InstancedMesh(ball, new THREE.MeshPhongMaterial({ color: EP_COLOUR }), nep);
      const mx = new THREE.Matrix4();
      for (let i = 0; i < nep; i++) {
        inst.setMatrixAt(i, mx.makeTranslation(m.eps[3 * i], m.eps[3 * i + 1], m.eps[3 * i + 2]));
      }
      this.groups.eps.add(inst);
    }
    // Program zero: the model's origin, where the work offset puts the program's X0 Y0 Z0;
    // an axis triad (X red, Y green, Z blue) a fifth of the model's size.
    {
      const len = Math.max(size * 0.2, 1e-3);
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array([0, 0, 0, len, 0, 0, 0, 0, 0, 0, len, 0, 0, 0, 0, 0, 0, len]), 3));
      g.setAttribute('color', new THREE.BufferAttribute(new Float32Array(ZERO_TRIAD.flatMap((c) => {
        const k = new THREE.Color(c);
        return [k.r, k.g, k.b, k.r, k.g, k.b];
      })), 3));
      const triad = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ vertexColors: true, depthTest: false }));
      triad.renderOrder = 10;
      this.groups.zero.add(triad);
    }
    // The stock block around the part (same layer): translucent faces, solid edges.
    const stock = m.summary?.stock_mm;
    if (stock) {
      const d = [0, 1, 2].map((k) => Math.max(stock.max[k] - stock.min[k], 1e-6));
      const box = new THREE.Mesh(
        new THREE.BoxGeometry(d[0], d[1], d[2]),
        stockMaterial(),
      );
      box.position.set(...[0, 1, 2].map((k) => 0.5 * (stock.min[k] + stock.max[k])));
      const eg = new THREE.BufferGeometry();
      eg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(boxEdges(stock)), 3));
      this.groups.zero.add(box, new THREE.LineSegments(eg, new THREE.LineBasicMaterial({ color: STOCK.edge })));
    }
    // The table grid: on the lowest plane of the stock (or the part), round spacing.
    const grid = tableGrid(stock || m.summary?.bbox_mm);
    if (grid) {
      const gg = new THREE.BufferGeometry();
      gg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(grid.lines), 3));
      this.groups.grid.add(new THREE.LineSegments(gg, new THREE.LineBasicMaterial({ color: GRID.line, transparent: true, opacity: 0.7 })));
      this.gridSpacing = grid.spacing;
    }
    if (m.cage.length) {
      const cg = new THREE.BufferGeometry();
      cg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(m.cage), 3));
      this.groups.cage.add(new THREE.LineSegments(cg, new THREE.LineBasicMaterial({ color: CAGE_COLOUR })));
      const pts = new THREE.Points(cg, new THREE.PointsMaterial({ color: CAGE_COLOUR, size: 4, sizeAttenuation: false }));
      this.groups.cage.add(pts);
    }
    this.fit();
  }

  #colourSurface() {
    if (!this.surface) return;
    const { indices: idx, patchIds } = this.model;
    const col = this.surface.geometry.getAttribute('color');
    const c = new THREE.Color();
    // Each colour converted to the renderer's space once (a few dozen colours, a million
    // corners on a fine tessellation).
    const linear = new Map();
    const rgb = (hex) => {
      let v = linear.get(hex);
      if (!v) {
        c.setHex(hex);
        v = [c.r, c.g, c.b];
        linear.set(hex, v);
      }
      return v;
    };
    const a = col.array;
    for (let corner = 0; corner < idx.length; corner++) {
      const hex = this.heat
        ? heatColour(this.heat.values[idx[corner]], this.heat.scallopMm)
        : PATCH_COLOURS[patchIds[(corner / 3) | 0] % PATCH_COLOURS.length];
      const [r, g, b] = rgb(hex);
      a[3 * corner] = r;
      a[3 * corner + 1] = g;
      a[3 * corner + 2] = b;
    }
    col.needsUpdate = true;
    this.colouredBy = this.heat;
    this.render();
  }

  /** The scallop heat map (one value per tessellation vertex, mm) or null for patches. */
  setHeat(values, scallopMm) {
    this.heat = values ? { values, scallopMm } : null;
    // Patch colours already shown: nothing to do (each plan clears the heat map twice).
    if (!this.heat && this.colouredBy === null) return;
    this.#colourSurface();
  }

  /** The rest area: `positions` (Float32Array, xyz per vertex, 3 vertices per triangle, on
   * the surface), `reasons` (Uint8Array, per triangle, an index of REST_REASONS) and
   * `regions` ([{centre_mm, why}], a ring each, so that small regions are seen); null for
   * none. Drawn over the surface, translucent. */
  setRest(rest) {
    this.#clear(this.groups.rest);
    if (rest && rest.positions.length) {
      const { positions: p, reasons } = rest;
      const geom = new THREE.BufferGeometry();
      geom.setAttribute('position', new THREE.BufferAttribute(new Float32Array(p), 3));
      const col = new Float32Array(p.length);
      const c = new THREE.Color();
      for (let t = 0; t < reasons.length; t++) {
        c.setHex((REST_REASONS[reasons[t]] || REST_REASONS[0]).colour);
        for (let k = 0; k < 3; k++) col.set([c.r, c.g, c.b], 9 * t + 3 * k);
      }
      geom.setAttribute('color', new THREE.BufferAttribute(col, 3));
      // In front of the surface (which is pushed back by its polygon offset), seen from
      // both sides, letting the surface's shading show through a little.
      const mat = new THREE.MeshBasicMaterial({
        vertexColors: true, side: THREE.DoubleSide, transparent: true, opacity: 0.8,
        depthWrite: false, polygonOffset: true, polygonOffsetFactor: -1, polygonOffsetUnits: -2,
      });
      const mesh = new THREE.Mesh(geom, mat);
      mesh.renderOrder = 1;
      this.groups.rest.add(mesh);
    }
    const regions = rest?.regions || [];
    if (regions.length) {
      const pos = new Float32Array(3 * regions.length);
      const col = new Float32Array(3 * regions.length);
      const c = new THREE.Color();
      regions.forEach((r, i) => {
        pos.set(r.centre_mm, 3 * i);
        c.setHex((REST_REASONS.find((x) => x.why === r.why) || REST_REASONS[0]).colour);
        col.set([c.r, c.g, c.b], 3 * i);
      });
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
      g.setAttribute('color', new THREE.BufferAttribute(col, 3));
      const mat = new THREE.PointsMaterial({
        size: 16, sizeAttenuation: false, vertexColors: true, map: ringTexture(),
        transparent: true, alphaTest: 0.3, depthWrite: false,
      });
      const rings = new THREE.Points(g, mat);
      rings.renderOrder = 2;
      this.groups.rest.add(rings);
    }
    this.render();
  }

  /** A space-filling curve's cells and tree: `cells` and `tree` (Float32Array, `x y z x y z`
   * per segment, on the surface, mm) and `across` (Uint8Array, per tree segment, 1 where it
   * crosses a patch side); null for none. Drawn over the surface, the tree over the cells. */
  setIsfc(isfc) {
    this.#clear(this.groups.isfc);
    if (isfc && isfc.cells.length) {
      const lines = (positions, colours, opacity) => {
        const g = new THREE.BufferGeometry();
        g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(positions), 3));
        g.setAttribute('color', new THREE.BufferAttribute(colours, 3));
        const mat = new THREE.LineBasicMaterial({ vertexColors: true, transparent: opacity < 1, opacity });
        return new THREE.LineSegments(g, mat);
      };
      const c = new THREE.Color();
      const fill = (n, colourOf) => {
        const col = new Float32Array(6 * n);
        for (let s = 0; s < n; s++) {
          c.setHex(colourOf(s));
          col.set([c.r, c.g, c.b, c.r, c.g, c.b], 6 * s);
        }
        return col;
      };
      const cells = lines(isfc.cells, fill(isfc.cells.length / 6, () => ISFC_LAYER.cell), 0.7);
      cells.renderOrder = 3;
      this.groups.isfc.add(cells);
      if (isfc.tree.length) {
        const tree = lines(isfc.tree, fill(isfc.tree.length / 6, (s) => (isfc.across[s] ? ISFC_LAYER.across : ISFC_LAYER.tree)), 1);
        tree.renderOrder = 4;
        this.groups.isfc.add(tree);
      }
    }
    this.render();
  }

  /** The watershed strategies' rectangles: `fills` (Float32Array, `x y z` per triangle
   * corner, on the surface, mm) with `kinds` (Uint8Array per triangle, an index into
   * RECT_LAYER.kinds), `outlines` and `arrows` (Float32Array, `x y z x y z` per segment);
   * null for none. Fills translucent over the surface, outlines and arrows over them. */
  setRects(rects) {
    this.#clear(this.groups.rects);
    if (rects && rects.fills.length) {
      const n = rects.kinds.length;
      const col = new Float32Array(9 * n);
      const c = new THREE.Color();
      for (let t = 0; t < n; t++) {
        c.setHex((RECT_LAYER.kinds[rects.kinds[t]] || RECT_LAYER.kinds[0]).colour);
        for (let k = 0; k < 3; k++) col.set([c.r, c.g, c.b], 9 * t + 3 * k);
      }
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(rects.fills), 3));
      g.setAttribute('color', new THREE.BufferAttribute(col, 3));
      const fills = new THREE.Mesh(g, new THREE.MeshBasicMaterial({
        vertexColors: true, side: THREE.DoubleSide, transparent: true, opacity: 0.8,
        depthWrite: false, polygonOffset: true, polygonOffsetFactor: -1, polygonOffsetUnits: -2,
      }));
      fills.renderOrder = 2;
      this.groups.rects.add(fills);
      for (const [positions, colour, order] of [[rects.outlines, RECT_LAYER.outline, 3], [rects.arrows, RECT_LAYER.arrow, 4]]) {
        const lg = new THREE.BufferGeometry();
        lg.setAttribute('position', new THREE.BufferAttribute(new Float32Array(positions), 3));
        const lines = new THREE.LineSegments(lg, new THREE.LineBasicMaterial({ color: colour }));
        lines.renderOrder = order;
        this.groups.rects.add(lines);
      }
    }
    this.render();
  }

  /** The path: `cl` (Float64Array, ball centres), `kinds` (Uint8Array), `patchIds`. */
  setPath(path) {
    this.#clear(this.groups.path);
    if (!path) {
      this.render();
      return;
    }
    const { cl, kinds, patchIds } = path;
    const n = kinds.length;
    // Segment i runs from move i-1 to move i and is of move i's kind.
    const count = new Array(KINDS.length).fill(0);
    for (let i = 1; i < n; i++) count[kinds[i]]++;
    const c = new THREE.Color();
    KINDS.forEach((kind, k) => {
      if (!count[k]) return;
      const pos = new Float32Array(6 * count[k]);
      const col = kind.colour === null ? new Float32Array(6 * count[k]) : null;
      let s = 0;
      for (let i = 1; i < n; i++) {
        if (kinds[i] !== k) continue;
        for (let e = 0; e < 2; e++) {
          const j = 3 * (i - 1 + e);
          pos.set([cl[j], cl[j + 1], cl[j + 2]], 6 * s + 3 * e);
          if (col) {
            c.setHex(pathColour(patchIds[i]));
            col.set([c.r, c.g, c.b], 6 * s + 3 * e);
          }
        }
        s++;
      }
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
      let mat;
      if (col) {
        g.setAttribute('color', new THREE.BufferAttribute(col, 3));
        // Dense finishing paths cover the surface line by line: let it show through.
        mat = new THREE.LineBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.6 });
      } else if (kind.dashed) {
        const dash = Math.max(this.sceneRadius || 1, 1e-3) * 0.02;
        mat = new THREE.LineDashedMaterial({ color: kind.colour, dashSize: dash, gapSize: dash });
      } else {
        mat = new THREE.LineBasicMaterial({ color: kind.colour });
      }
      const lines = new THREE.LineSegments(g, mat);
      if (kind.dashed) lines.computeLineDistances();
      lines.name = kind.name;
      this.groups.path.add(lines);
    });
    this.render();
  }

  /** The tool at a pose: `centre` (ball centre), `axis` (unit, tip to spindle) and the
   * tool's sizes (mm): `radius`, `shankRadius`, `fluteLength`, `shankLength`,
   * `holderRadius`, `holderLength`. null hides it. */
  setTool(t) {
    if (!t) {
      this.#clear(this.groups.tool);
      this.toolKey = null;
      this.render();
      return;
    }
    const key = [t.radius, t.shankRadius, t.fluteLength, t.shankLength, t.holderRadius, t.holderLength].join();
    if (key !== this.toolKey) {
      this.#clear(this.groups.tool);
      this.toolKey = key;
      const steel = new THREE.MeshPhongMaterial({ color: 0xb8bec8, shininess: 80 });
      const flutes = new THREE.MeshPhongMaterial({ color: 0x8a93a3, shininess: 60 });
      const holder = new THREE.MeshPhongMaterial({ color: 0x4a5568, transparent: true, opacity: 0.35, depthWrite: false });
      const tool = new THREE.Group();
      tool.add(new THREE.Mesh(new THREE.SphereGeometry(t.radius, 32, 16), flutes));
      const cyl = (r, from, to, mat) => {
        if (to <= from) return;
        const m = new THREE.Mesh(new THREE.CylinderGeometry(r, r, to - from, 32, 1, true), mat);
        m.position.y = (from + to) / 2;
        tool.add(m);
      };
      cyl(t.radius, 0, t.fluteLength, flutes);
      cyl(t.shankRadius, t.fluteLength, t.shankLength, steel);
      cyl(t.holderRadius, t.shankLength, t.shankLength + t.holderLength, holder);
      this.groups.tool.add(tool);
      this.tool = tool;
    }
    this.tool.position.set(...t.centre);
    this.tool.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), new THREE.Vector3(...t.axis).normalize());
    this.render();
  }

  /** Shows or hides layers: `{surface, rest, isfc, rects, path, tool, cage, eps, zero}`. */
  setLayers(layers) {
    Object.assign(this.layers, layers);
    this.render();
  }

  /** Centres the model and frames it, from the standard view `name` (see VIEWS; the
   * iso view by default). */
  fit(name = 'iso') {
    if (!this.surface) return;
    const s = this.surface.geometry.boundingSphere;
    this.focus([s.center.x, s.center.y, s.center.z], s.radius, VIEWS[name] || VIEWS.iso);
    this.viewName = VIEWS[name] ? name : 'iso';
  }

  /** Frames a sphere of `radius` (mm) round `centre`, seen from direction `from` (a unit
   * vector from the centre towards the viewer; the current direction if null). */
  focus(centre, radius, from = null) {
    const dir = from ? new THREE.Vector3(...from).normalize()
      : this.camera.position.clone().sub(this.controls.target).normalize();
    const dist = radius / Math.sin(THREE.MathUtils.degToRad(FOV_DEG / 2)) * 1.05;
    this.controls.target.set(...centre);
    this.camera.position.copy(this.controls.target).addScaledVector(dir, dist);
    this.camera.near = Math.max(dist / 1000, 1e-4);
    this.camera.far = Math.max(dist, this.sceneRadius || 1) * 100;
    if (this.camera.isOrthographicCamera) this.#orthoFrustum(radius * 1.05);
    this.camera.zoom = 1;
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.render();
  }

  /** The orthographic camera's box: `half` mm high from the centre, to the canvas's aspect. */
  #orthoFrustum(half) {
    const aspect = this.canvas.clientWidth / Math.max(1, this.canvas.clientHeight) || 1;
    Object.assign(this.camera, { left: -half * aspect, right: half * aspect, top: half, bottom: -half });
  }

  /** Switches between the perspective and the orthographic (parallel, true-scale) camera,
   * keeping where it looks from and what it frames. */
  setOrtho(on) {
    if (!!on === this.camera.isOrthographicCamera) return;
    const old = this.camera;
    const target = this.controls.target.clone();
    const dist = old.position.distanceTo(target);
    const cam = on ? new THREE.OrthographicCamera(-1, 1, 1, -1, old.near, old.far)
      : new THREE.PerspectiveCamera(FOV_DEG, old.aspect || 1, old.near, old.far);
    cam.up.copy(old.up);
    cam.position.copy(old.position);
    for (const c of [...old.children]) cam.add(c); // the light follows the viewer
    this.scene.remove(old);
    this.scene.add(cam);
    this.camera = cam;
    if (on) {
      // What the perspective camera showed at the target, as large.
      const half = dist * Math.tan(THREE.MathUtils.degToRad(FOV_DEG / 2)) / (old.zoom || 1);
      this.#orthoFrustum(half);
    } else {
      cam.aspect = this.canvas.clientWidth / Math.max(1, this.canvas.clientHeight) || 1;
    }
    cam.lookAt(target);
    cam.updateProjectionMatrix();
    this.controls.object = cam;
    this.controls.update();
    this.ortho = !!on;
    this.render();
  }

  /** The radius of the model's bounding sphere (mm). */
  get modelRadius() {
    return this.sceneRadius || 1;
  }

  /** Renders now and returns the frame's pixels, RGBA rows (for tests and diagnostics). */
  snapshot() {
    this.renderNow();
    const gl = this.renderer.getContext();
    const w = gl.drawingBufferWidth;
    const h = gl.drawingBufferHeight;
    const px = new Uint8Array(4 * w * h);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    return px;
  }

  /** Renders now and counts pixels that are not background. */
  countPixels() {
    const px = this.snapshot();
    const w = this.renderer.getContext().drawingBufferWidth;
    const h = this.renderer.getContext().drawingBufferHeight;
    const bg = [BACKGROUND >> 16 & 255, BACKGROUND >> 8 & 255, BACKGROUND & 255];
    let drawn = 0;
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - bg[0]) + Math.abs(px[i + 1] - bg[1]) + Math.abs(px[i + 2] - bg[2]) > 24) drawn++;
    }
    return { drawn, total: w * h };
  }

  /** Arrow keys orbit, Shift+arrows pan, + and - zoom, F fits. */
  #bindKeys() {
    this.canvas.addEventListener('keydown', (e) => {
      const cam = this.camera;
      const target = this.controls.target;
      const offset = cam.position.clone().sub(target);
      const right = new THREE.Vector3().crossVectors(cam.up, offset).normalize(); // screen right
      const turn = (axis, angle) => {
        offset.applyQuaternion(new THREE.Quaternion().setFromAxisAngle(axis, angle));
      };
      const pan = (dx, dy) => {
        const step = offset.length() * 0.05;
        const up = new THREE.Vector3().crossVectors(offset, right).normalize(); // screen up
        const d = right.multiplyScalar(dx * step).add(up.multiplyScalar(dy * step));
        target.add(d);
        cam.position.add(d);
      };
      const arrows = { ArrowLeft: [-1, 0], ArrowRight: [1, 0], ArrowUp: [0, 1], ArrowDown: [0, -1] };
      if (arrows[e.key]) {
        const [dx, dy] = arrows[e.key];
        if (e.shiftKey) pan(dx, dy);
        else {
          if (dx) turn(new THREE.Vector3(0, 0, 1), -dx * ORBIT_STEP_RAD);
          if (dy) {
            const next = offset.clone().applyQuaternion(new THREE.Quaternion().setFromAxisAngle(right, -dy * ORBIT_STEP_RAD));
            if (Math.abs(next.clone().normalize().z) < 0.995) offset.copy(next);
          }
          cam.position.copy(target).add(offset);
        }
      } else if ((e.key === '+' || e.key === '=' || e.key === '-' || e.key === '_') && cam.isOrthographicCamera) {
        // A parallel camera zooms; moving it closer changes nothing on screen.
        cam.zoom *= e.key === '+' || e.key === '=' ? 1.15 : 1 / 1.15;
        cam.updateProjectionMatrix();
      } else if (e.key === '+' || e.key === '=') {
        cam.position.copy(target).addScaledVector(offset, 1 / 1.15);
      } else if (e.key === '-' || e.key === '_') {
        cam.position.copy(target).addScaledVector(offset, 1.15);
      } else if (e.key === 'f' || e.key === 'F') {
        this.fit();
      } else {
        return;
      }
      e.preventDefault();
      this.controls.update();
      this.render();
    });
  }

  dispose() {
    this.resizer.disconnect();
    this.controls.dispose();
    this.renderer.dispose();
  }
}

/** A white ring on transparent ground, for the rest-region markers (tinted per point). */
let ring = null;
function ringTexture() {
  if (ring) return ring;
  const n = 64;
  const c = document.createElement('canvas');
  c.width = n;
  c.height = n;
  const g = c.getContext('2d');
  g.strokeStyle = '#fff';
  g.lineWidth = n * 0.14;
  g.beginPath();
  g.arc(n / 2, n / 2, n * 0.36, 0, 2 * Math.PI);
  g.stroke();
  ring = new THREE.CanvasTexture(c);
  return ring;
}
