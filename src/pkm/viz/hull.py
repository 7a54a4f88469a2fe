"""Convex hulls of a few points, as triangle meshes: the platform's polygon or prism, the base's layers.

Exact for the handful of points a mechanism's frames give (every triple of points tried as a face); no scipy.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np


def unique_points(points: np.ndarray, tol: float) -> np.ndarray:
    """``points`` (k, 3) without repeats (any two within ``tol`` [m] count once), in their order."""
    out: list[np.ndarray] = []
    for p in points:
        if not any(np.linalg.norm(p - o) <= tol for o in out):
            out.append(p)
    return np.array(out).reshape(-1, 3)


def _hull2d(xy: np.ndarray, tol: float) -> list[int]:
    """Indices of the convex hull of 2-D points, counter-clockwise, collinear points dropped."""
    order = sorted(range(len(xy)), key=lambda i: (xy[i, 0], xy[i, 1]))

    def cross(o, a, b):
        return (xy[a, 0] - xy[o, 0]) * (xy[b, 1] - xy[o, 1]) - (xy[a, 1] - xy[o, 1]) * (xy[b, 0] - xy[o, 0])

    lower: list[int] = []
    for i in order:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], i) <= tol:
            lower.pop()
        lower.append(i)
    upper: list[int] = []
    for i in reversed(order):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], i) <= tol:
            upper.pop()
        upper.append(i)
    return lower[:-1] + upper[:-1]


def convex_hull(points: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices (k, 3) and triangles (m, 3) of the convex hull of a few points; None if flatter than a plane.

    Coplanar points give their polygon (one face); otherwise every face of the solid hull
    gets its own vertices (flat shading), triangles wound counter-clockwise seen from outside.
    """
    pts = unique_points(np.asarray(points, dtype=float), tol)
    if len(pts) < 3:
        return None
    centre = pts.mean(axis=0)
    _, s, vt = np.linalg.svd(pts - centre)
    scale = max(float(s[0]), 1.0)
    if s[1] <= tol * scale:
        return None
    rings: list[np.ndarray] = []
    if len(pts) == 3 or s[2] <= tol * scale:
        ring = _hull2d((pts - centre) @ vt[:2].T, tol * scale)
        rings.append(pts[ring])
    else:
        planes: list[tuple[np.ndarray, float]] = []
        for i, j, k in combinations(range(len(pts)), 3):
            n = np.cross(pts[j] - pts[i], pts[k] - pts[i])
            if np.linalg.norm(n) <= tol * scale:
                continue
            n /= np.linalg.norm(n)
            d = (pts - pts[i]) @ n
            if np.all(d >= -tol):
                n, d = -n, -d
            elif not np.all(d <= tol):
                continue
            off = float(n @ pts[i])
            if any(np.allclose(n, n2, atol=1e-9) and abs(off - o2) <= tol for n2, o2 in planes):
                continue
            planes.append((n, off))
            on = pts[np.abs(d) <= tol]
            u = on[1] - on[0]
            u /= np.linalg.norm(u)
            basis = np.array([u, np.cross(n, u)])
            rings.append(on[_hull2d((on - on.mean(axis=0)) @ basis.T, tol * scale)])
    return _fans(rings)


def _fans(rings: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and fan triangles of convex polygons (each an ordered ring of points)."""
    verts: list[np.ndarray] = []
    faces: list[tuple[int, int, int]] = []
    for ring in rings:
        base = len(verts)
        verts.extend(ring)
        faces.extend((base, base + i, base + i + 1) for i in range(1, len(ring) - 1))
    return np.array(verts), np.array(faces, dtype=int)


def layered_polygons(points: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Polygons through points lying in parallel planes, else their convex hull.

    The base anchors of a mechanism are coplanar (one polygon) or, like the hexapod's two
    3-RUS, lie in a few parallel layers of three or more points (one polygon per layer,
    across the direction of least spread); otherwise they get their solid convex hull.
    """
    pts = unique_points(np.asarray(points, dtype=float), tol)
    if len(pts) < 3:
        return None
    centre = pts.mean(axis=0)
    _, s, vt = np.linalg.svd(pts - centre)
    if len(pts) > 3 and s[2] > tol * max(float(s[0]), 1.0):
        height = (pts - centre) @ vt[2]
        order = np.argsort(height)
        cuts = np.flatnonzero(np.diff(height[order]) > 1e3 * tol) + 1
        layers = np.split(order, cuts)
        hulls = [convex_hull(pts[layer], tol) if len(layer) >= 3 else None for layer in layers]
        if len(layers) > 1 and all(h is not None and len(h[1]) == len(h[0]) - 2 for h in hulls):
            return _fans([h[0] for h in hulls if h is not None])
    return convex_hull(pts, tol)
