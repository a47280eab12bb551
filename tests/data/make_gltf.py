#!/usr/bin/env python3
"""Writes quad_scene.gltf: a floor, an emissive ceiling quad (KHR emissive factor 1, scaled
in the scene file), a mirror quad (metallic 1, roughness 0) and a glass quad
(KHR_materials_transmission + KHR_materials_ior), one mesh each, with an embedded buffer."""
import base64, json, struct

def quad(y, size, normal_down):
    s = size / 2
    pos = [(-s, y, -s), (s, y, -s), (s, y, s), (-s, y, s)]
    idx = [0, 2, 1, 0, 3, 2] if not normal_down else [0, 1, 2, 0, 2, 3]
    return pos, idx

meshes = [("floor", quad(0.0, 2.0, False), 0), ("light", quad(1.0, 0.5, True), 1),
          ("mirror", quad(0.3, 0.3, False), 2), ("glass", quad(0.5, 0.3, False), 3)]
blob = b""; views = []; accessors = []; gl_meshes = []
for name, (pos, idx), mat in meshes:
    p = b"".join(struct.pack("<3f", *v) for v in pos)
    i = b"".join(struct.pack("<H", k) for k in idx) + b"\0\0"
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(p), "target": 34962}); blob += p
    views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(idx) * 2, "target": 34963}); blob += i
    mins = [min(v[a] for v in pos) for a in range(3)]; maxs = [max(v[a] for v in pos) for a in range(3)]
    accessors.append({"bufferView": len(views) - 2, "componentType": 5126, "count": 4, "type": "VEC3", "min": mins, "max": maxs})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": len(idx), "type": "SCALAR"})
    gl_meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1, "material": mat}]})
doc = {
    "asset": {"version": "2.0", "generator": "photonvr tests/data/make_gltf.py"},
    "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"],
    "scene": 0, "scenes": [{"nodes": [0, 1, 2, 3]}],
    "nodes": [{"mesh": m} for m in range(4)],
    "meshes": gl_meshes,
    "materials": [
        {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 0.125, 1], "metallicFactor": 0, "roughnessFactor": 1}},
        {"name": "lamp", "emissiveFactor": [1.0, 0.5, 0.25], "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}},
        {"name": "chrome", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1], "metallicFactor": 1, "roughnessFactor": 0}},
        {"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
         "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.45}}},
    ],
    "buffers": [{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": views, "accessors": accessors,
}
open("quad_scene.gltf", "w").write(json.dumps(doc, indent=1) + "\n")
