#!/usr/bin/env python3
"""Writes the example scene files in this directory (rerun after changing a scene here).

Each scene is small enough to read; all textures are procedural and inline."""
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def compact(value, indent=0):
    """JSON with one key per line but arrays of numbers kept on one line."""
    pad = "  " * (indent + 1)
    if isinstance(value, dict):
        items = [f'{pad}{json.dumps(k)}: {compact(v, indent + 1)}' for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + "  " * indent + "}"
    if isinstance(value, list) and value and all(isinstance(v, (int, float)) for v in value):
        return "[" + ", ".join(json.dumps(round(v, 6) if isinstance(v, float) else v) for v in value) + "]"
    if isinstance(value, list):
        return "[\n" + ",\n".join(pad + compact(v, indent + 1) for v in value) + "\n" + "  " * indent + "]"
    return json.dumps(value)


def write(name, scene):
    with open(os.path.join(HERE, name), "w") as f:
        f.write(compact(scene) + "\n")


def checker(size, cell, a, b):
    px = []
    for y in range(size):
        for x in range(size):
            px += a if ((x // cell) + (y // cell)) % 2 == 0 else b
    return px


# 1. Gouraud triangle: one triangle, red/green/blue corners.
write("gouraud-triangle.json", {
    "format": "gpubridge-scene", "version": 1,
    "comment": "One Gouraud-shaded triangle on a dark blue background.",
    "framebuffer": {"width": 160, "height": 120},
    "clear": {"color": [0.05, 0.05, 0.2]},
    "draws": [{"vertices": [
        {"x": 80, "y": 10, "r": 1, "g": 0, "b": 0},
        {"x": 150, "y": 110, "r": 0, "g": 1, "b": 0},
        {"x": 10, "y": 110, "r": 0, "g": 0, "b": 1}]}],
})

# 2. Depth test: two triangles crossing in depth; the Z buffer resolves the intersection.
write("depth-intersection.json", {
    "format": "gpubridge-scene", "version": 1,
    "comment": "Two flat triangles that pierce each other; z_test LESS with z_write.",
    "framebuffer": {"width": 160, "height": 120},
    "clear": {"color": [0, 0, 0], "depth": 1.0},
    "draws": [
        {"z_test": True, "z_write": True, "z_func": "LESS", "gouraud": False, "color": [1, 0.5, 0],
         "vertices": [[10, 10, 0.2], [150, 60, 0.8], [10, 110, 0.2]]},
        {"z_test": True, "z_write": True, "z_func": "LESS", "gouraud": False, "color": [0, 0.6, 1],
         "vertices": [[150, 10, 0.2], [150, 110, 0.2], [10, 60, 0.8]]},
    ],
})

# 3. Perspective-correct textured floor: a checkerboard quad receding to the horizon
#    (w from 1 at the bottom to 16 at the top; u, v repeat 8 times).
near_y, far_y = 119.0, 30.0
w_near, w_far = 1.0, 16.0
floor = [
    {"x": -40, "y": near_y, "z": 0.1, "w": w_near, "u": 0, "v": 0},
    {"x": 200, "y": near_y, "z": 0.1, "w": w_near, "u": 8, "v": 0},
    {"x": 200 - (240 / 2) * (1 - w_near / w_far), "y": far_y, "z": 0.9, "w": w_far, "u": 8, "v": 8},
    {"x": -40 + (240 / 2) * (1 - w_near / w_far), "y": far_y, "z": 0.9, "w": w_far, "u": 0, "v": 8},
]
write("textured-floor.json", {
    "format": "gpubridge-scene", "version": 1,
    "comment": "A perspective-correct checkerboard floor (REPEAT, nearest) under a sky gradient.",
    "framebuffer": {"width": 160, "height": 120},
    "clear": {"color": [0.5, 0.7, 1.0]},
    "textures": [{"name": "checker", "width": 16, "height": 16, "format": "RGB565", "wrap": "REPEAT",
                  "rgba": checker(16, 8, [230, 230, 230, 255], [40, 40, 60, 255])}],
    "draws": [
        {"vertices": [[0, 0, 0, 1, 0.2, 0.3, 0.8], [160, 0, 0, 1, 0.2, 0.3, 0.8], [160, 30, 0, 1, 0.8, 0.8, 1.0],
                      [0, 0, 0, 1, 0.2, 0.3, 0.8], [160, 30, 0, 1, 0.8, 0.8, 1.0], [0, 30, 0, 1, 0.8, 0.8, 1.0]]},
        {"texture": "checker", "texture_mode": "modulate",
         "vertices": [floor[0], floor[1], floor[2], floor[0], floor[2], floor[3]]},
    ],
})

# 4. Alpha blending: three translucent overlapping triangles.
def tri(cx, cy, r, color):
    import math
    pts = []
    for k in range(3):
        a = math.pi / 2 + k * 2 * math.pi / 3
        pts.append([cx + r * math.cos(a), cy - r * math.sin(a)])
    return {"blend": "ALPHA", "color": color, "vertices": pts}

write("alpha-blend.json", {
    "format": "gpubridge-scene", "version": 1,
    "comment": "Three triangles with alpha 0.5 blended over a grey background (BLEND = ALPHA).",
    "framebuffer": {"width": 160, "height": 120},
    "clear": {"color": [0.5, 0.5, 0.5]},
    "draws": [tri(60, 55, 45, [1, 0, 0, 0.5]), tri(100, 55, 45, [0, 1, 0, 0.5]), tri(80, 80, 45, [0, 0, 1, 0.5])],
})

# 5. Dithered gradient on a 2-bit-per-channel framebuffer (the donut-ASIC look).
write("dither-rgba2222.json", {
    "format": "gpubridge-scene", "version": 1,
    "comment": "A full-screen colour gradient stored as RGBA2222 with ordered dithering.",
    "framebuffer": {"width": 160, "height": 120, "format": "RGBA2222"},
    "clear": {"color": [0, 0, 0]},
    "draws": [{"dither": True, "vertices": [
        [0, 0, 0, 1, 0, 0, 0], [160, 0, 0, 1, 1, 0.5, 0], [160, 120, 0, 1, 1, 1, 1],
        [0, 0, 0, 1, 0, 0, 0], [160, 120, 0, 1, 1, 1, 1], [0, 120, 0, 1, 0, 0.5, 1]]}],
})
