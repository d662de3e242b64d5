#!/usr/bin/env python3
"""Evaluates the T-spline printed by dump.cpp exactly (Cox-de Boor, rational sum) at the
corners, edge midpoints and centre of every face, just inside the face (1e-12 of its size)
so that no point sits on a knot. Writes one line per point: face s t x y z (mm)."""
import sys

INSET = 1e-12
FRACTIONS = [INSET, 0.5, 1.0 - INSET]


def bspline(knots, x):
    """Cubic B-spline with five knots at x (half-open spans)."""
    def rec(i, p):
        if p == 0:
            return 1.0 if knots[i] <= x < knots[i + 1] else 0.0
        out = 0.0
        if knots[i + p] > knots[i]:
            out += (x - knots[i]) / (knots[i + p] - knots[i]) * rec(i, p - 1)
        if knots[i + p + 1] > knots[i + 1]:
            out += (knots[i + p + 1] - x) / (knots[i + p + 1] - knots[i + 1]) * rec(i + 1, p - 1)
        return out
    return rec(0, 3)


def main(dump, out, source):
    faces = []
    for line in open(dump):
        t = line.split()
        if t[0] == 'face':
            faces.append((t[1], [float(x) for x in t[2:6]], []))
        elif t[0] == 'blend':
            ui, vi = t.index('u'), t.index('v')
            u = [float(x) for x in t[ui + 1:vi]]
            v = [float(x) for x in t[vi + 1:]]
            if len(u) != 5 or len(v) != 5:
                sys.exit(f'{dump}: a blending function without five knots: {line}')
            faces[-1][2].append(([float(x) for x in t[1:4]], float(t[4]), u, v))
    with open(out, 'w') as f:
        f.write(f'# {source}\n')
        f.write('# The T-spline as GrapeTec/T-SPLINE reads it (its own knot vectors and control\n')
        f.write('# points), evaluated exactly at the corners, edge midpoints and centre of each\n')
        f.write('# face, 1e-12 of the face inside. Made by scripts/grapetec/reference.\n')
        f.write('# face s t x y z (GrapeTec parameters; mm)\n')
        for name, (s0, s1, t0, t1), blends in faces:
            for a in FRACTIONS:
                for b in FRACTIONS:
                    s, t = s0 + (s1 - s0) * a, t0 + (t1 - t0) * b
                    num, den = [0.0, 0.0, 0.0], 0.0
                    for p, w, u, v in blends:
                        n = w * bspline(u, s) * bspline(v, t)
                        den += n
                        for i in range(3):
                            num[i] += n * p[i]
                    if den <= 0.0:
                        sys.exit(f'{dump}: face {name} has no blending function at ({s}, {t})')
                    x, y, z = (c / den for c in num)
                    f.write(f'{name} {s:.15g} {t:.15g} {x:.13g} {y:.13g} {z:.13g}\n')


if __name__ == '__main__':
    main(*sys.argv[1:4])
