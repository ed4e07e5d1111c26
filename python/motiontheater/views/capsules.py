"""A simple body for an armature: a capsule along each bone, bound wholly to the node it turns
with, so that a viewer of an exported file shows a figure and not only points."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .armature import Armature

AROUND = 8  # vertices around each ring
LATITUDES = np.radians([-60.0, -30.0, 0.0])  # rings of the lower cap; the upper mirrors them
SHORTEST = 0.005  # metres: a bone shorter than this (a joint on top of its parent) gets no capsule


@dataclass(frozen=True)
class Body:
    """Triangles in the bind pose (metres, the armature's world axes): ``positions`` and
    ``normals`` (vertices, 3) float32, ``nodes`` (vertices,) the armature node each vertex
    follows, ``triangles`` (triangles, 3) vertex indices, counter-clockwise seen from outside."""

    positions: np.ndarray
    normals: np.ndarray
    nodes: np.ndarray
    triangles: np.ndarray


def capsules(armature: Armature) -> Body:
    """A capsule from each node to each of its children, as thick as a tenth of the bone
    (1 to 5 cm), following the parent node."""
    points = armature.rest_world[:, :3, 3]
    positions, normals, nodes, triangles = [], [], [], []
    count = 0
    for child in range(1, armature.nodes):
        parent = int(armature.parents[child])
        a, b = points[parent], points[child]
        length = float(np.linalg.norm(b - a))
        if length < SHORTEST:
            continue
        p, n, t = _capsule(a, b, float(np.clip(0.1 * length, 0.01, 0.05)))
        positions.append(p)
        normals.append(n)
        nodes.append(np.full(len(p), parent))
        triangles.append(t + count)
        count += len(p)
    if not positions:
        raise ValueError("the skeleton's bones are all shorter than 5 mm: there is no body to draw (body=false)")
    return Body(
        np.concatenate(positions).astype(np.float32),
        np.concatenate(normals).astype(np.float32),
        np.concatenate(nodes),
        np.concatenate(triangles),
    )


def _capsule(a: np.ndarray, b: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    w = (b - a) / np.linalg.norm(b - a)
    u = np.cross(w, np.eye(3)[np.argmin(np.abs(w))])
    u /= np.linalg.norm(u)
    v = np.cross(w, u)
    around = 2 * np.pi * np.arange(AROUND) / AROUND
    radial = np.cos(around)[:, None] * u + np.sin(around)[:, None] * v  # u x v = w: counter-clockwise about w
    rings = [(phi, a) for phi in LATITUDES] + [(-phi, b) for phi in LATITUDES[::-1]]
    normals = [-w] + [np.cos(phi) * radial + np.sin(phi) * w for phi, _ in rings] + [w]
    centres = [a] + [np.broadcast_to(c, (AROUND, 3)) for _, c in rings] + [b]
    normal = np.vstack(normals)
    position = np.vstack(centres) + radius * normal
    last, top = len(rings) - 1, len(position) - 1
    faces = [np.column_stack([np.zeros(AROUND, int), _ring(0, 1), _ring(0)])]
    for k in range(last):
        faces.append(np.column_stack([_ring(k), _ring(k, 1), _ring(k + 1, 1)]))
        faces.append(np.column_stack([_ring(k), _ring(k + 1, 1), _ring(k + 1)]))
    faces.append(np.column_stack([np.full(AROUND, top), _ring(last), _ring(last, 1)]))
    return position, normal, np.vstack(faces)


def _ring(k: int, shift: int = 0) -> np.ndarray:
    """The vertex indices of ring k (after the bottom pole), each ``shift`` places on."""
    return 1 + k * AROUND + (np.arange(AROUND) + shift) % AROUND
