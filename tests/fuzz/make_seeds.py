#!/usr/bin/env python3
"""Writes the hand-made seed files of tests/fuzz/seeds/ (small valid inputs of every format
the fuzz targets read, where the repository has no file of that format). Deterministic:
running it again rewrites the same bytes. Usage: python3 tests/fuzz/make_seeds.py"""
import base64
import json
import os
import struct

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seeds")

# A tetrahedron with outward faces (counter-clockwise seen from outside), in mm.
V = [(0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (0.0, 10.0, 0.0), (0.0, 0.0, 10.0)]
F = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]


def put(rel, data):
    path = os.path.join(HERE, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


def normal(f):
    a, b, c = (V[i] for i in f)
    u = [b[k] - a[k] for k in range(3)]
    w = [c[k] - a[k] for k in range(3)]
    n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
    s = sum(x * x for x in n) ** 0.5
    return [x / s for x in n]


def stl():
    out = ["solid tetra"]
    for f in F:
        out.append("  facet normal %g %g %g" % tuple(normal(f)))
        out.append("    outer loop")
        out += ["      vertex %g %g %g" % V[i] for i in f]
        out += ["    endloop", "  endfacet"]
    out.append("endsolid tetra")
    put("stl/tetra-ascii.stl", "\n".join(out) + "\n")
    b = bytearray(b"binary tetra".ljust(80, b" "))
    b += struct.pack("<I", len(F))
    for f in F:
        b += struct.pack("<3f", *normal(f))
        for i in f:
            b += struct.pack("<3f", *V[i])
        b += struct.pack("<H", 0)
    put("stl/tetra-binary.stl", bytes(b))


def ply_mesh():
    head = "ply\nformat %s 1.0\ncomment tetrahedron\nelement vertex 4\nproperty float x\nproperty float y\n" \
           "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
    body = "".join("%g %g %g\n" % v for v in V) + "".join("3 %d %d %d\n" % f for f in F)
    put("ply-mesh/tetra-ascii.ply", head % "ascii" + body)
    for fmt, e in (("binary_little_endian", "<"), ("binary_big_endian", ">")):
        b = bytearray((head % fmt).encode())
        for v in V:
            b += struct.pack(e + "3f", *v)
        for f in F:
            b += struct.pack(e + "B3i", 3, *f)
        put("ply-mesh/tetra-%s.ply" % fmt.replace("_", "-"), bytes(b))
    # A quad face (Assimp triangulates it) and a vertex with a normal.
    put("ply-mesh/square-ascii.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
        "property float nx\nproperty float ny\nproperty float nz\nelement face 1\n"
        "property list uchar uint vertex_indices\nend_header\n"
        "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n")


def off():
    body = "".join("%g %g %g\n" % v for v in V) + "".join("3 %d %d %d\n" % f for f in F)
    put("off/tetra.off", "OFF\n# tetrahedron\n%d %d 6\n" % (len(V), len(F)) + body)
    put("off/square-coff.off", "COFF\n4 1 0\n0 0 0 255 0 0 255\n1 0 0 255 0 0 255\n"
                               "1 1 0 255 0 0 255\n0 1 0 255 0 0 255\n4 0 1 2 3\n")


def gltf_doc(buffer_uri, nested):
    pos = b"".join(struct.pack("<3f", *v) for v in V)
    idx = b"".join(struct.pack("<3H", *f) for f in F)
    data = pos + idx
    nodes = [{"mesh": 0, "name": "tetra", "translation": [1.0, 2.0, 3.0]}]
    scene_nodes = [0]
    if nested:  # a small hierarchy: root -> child (scaled, rotated) -> mesh
        nodes = [{"name": "root", "children": [1]},
                 {"name": "child", "children": [2], "scale": [2.0, 2.0, 2.0], "rotation": [0.0, 0.0, 0.7071068, 0.7071068]},
                 {"mesh": 0, "name": "tetra", "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 5, 0, 0, 1]}]
    doc = {
        "asset": {"version": "2.0", "generator": "loom make_seeds.py"},
        "scene": 0,
        "scenes": [{"nodes": scene_nodes}],
        "nodes": nodes,
        "meshes": [{"name": "tetra", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [10, 10, 10]},
            {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx), "target": 34963}],
        "buffers": [{"byteLength": len(data)}],
    }
    if buffer_uri:
        doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    return doc, data


def gltf():
    for nested in (False, True):
        doc, _ = gltf_doc(True, nested)
        put("gltf/tetra%s.gltf" % ("-nested" if nested else ""), json.dumps(doc, indent=1) + "\n")
        doc, data = gltf_doc(False, nested)
        js = json.dumps(doc).encode()
        js += b" " * (-len(js) % 4)
        data += b"\0" * (-len(data) % 4)
        body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(data), 0x004E4942) + data
        put("glb/tetra%s.glb" % ("-nested" if nested else ""), struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)


def dae():
    pos = " ".join("%g %g %g" % v for v in V)
    idx = " ".join("%d %d %d" % f for f in F)
    put("dae/tetra.dae", f"""<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="millimeter" meter="0.001"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries>
    <geometry id="tetra-mesh" name="tetra">
      <mesh>
        <source id="tetra-pos">
          <float_array id="tetra-pos-array" count="12">{pos}</float_array>
          <technique_common>
            <accessor source="#tetra-pos-array" count="4" stride="3">
              <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
            </accessor>
          </technique_common>
        </source>
        <vertices id="tetra-vtx"><input semantic="POSITION" source="#tetra-pos"/></vertices>
        <triangles count="4"><input semantic="VERTEX" source="#tetra-vtx" offset="0"/><p>{idx}</p></triangles>
        <polylist count="1"><input semantic="VERTEX" source="#tetra-vtx" offset="0"/><vcount>3</vcount><p>1 2 3</p></polylist>
      </mesh>
    </geometry>
  </library_geometries>
  <library_nodes>
    <node id="part" name="part"><instance_geometry url="#tetra-mesh"/></node>
  </library_nodes>
  <library_visual_scenes>
    <visual_scene id="scene" name="scene">
      <node id="root" name="root">
        <translate>1 2 3</translate>
        <rotate>0 0 1 90</rotate>
        <node id="child" name="child">
          <matrix>1 0 0 5 0 1 0 0 0 0 1 0 0 0 0 1</matrix>
          <instance_geometry url="#tetra-mesh"/>
        </node>
        <instance_node url="#part"/>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
""")


def obj():
    put("obj/groups.obj", """# two groups, a quad, negative (relative) indices, normals and texture coordinates
mtllib missing.mtl
o plate
v 0 0 0
v 10 0 0
v 10 10 0
v 0 10 0
vn 0 0 1
vt 0 0
vt 1 0
vt 1 1
vt 0 1
g top
usemtl steel
f 1/1/1 2/2/1 3/3/1 4/4/1
g tip
v 5 5 8
f -1 -5 -4
f -1 -4 -3
s off
l 1 2
""")


CLOUD = [(0.0, 0.0, 0.0), (1.5, -2.0, 3.25), (4.0, 4.0, -1.0), (-7.5, 0.5, 2.0)]


def ply_cloud():
    head = "ply\nformat %s 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
           "property uchar intensity\nelement camera 1\nproperty double px\nend_header\n"
    put("ply-cloud/points-ascii.ply", head % "ascii" + "".join("%g %g %g 7\n" % p for p in CLOUD) + "0.5\n")
    for fmt, e in (("binary_little_endian", "<"), ("binary_big_endian", ">")):
        b = bytearray((head % fmt).encode())
        for p in CLOUD:
            b += struct.pack(e + "3fB", *p, 7)
        b += struct.pack(e + "d", 0.5)
        put("ply-cloud/points-%s.ply" % fmt.replace("_", "-"), bytes(b))
    put("ply-cloud/points-nan-ascii.ply", "ply\r\nformat ascii 1.0\r\nelement vertex 3\r\nproperty double x\r\n"
        "property double y\r\nproperty double z\r\nend_header\r\n1 2 3\r\nnan 0 0\r\n4 5 inf\r\n")


def pcd_header(fields, sizes, types, counts, n, data):
    return ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS %s\nSIZE %s\nTYPE %s\nCOUNT %s\n"
            "WIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\nDATA %s\n"
            % (fields, sizes, types, counts, n, n, data))


def lzf_literals(raw):
    """LZF stream of literal runs only (a control byte 0..31 = run length - 1): valid LZF."""
    out = bytearray()
    for i in range(0, len(raw), 32):
        chunk = raw[i:i + 32]
        out.append(len(chunk) - 1)
        out += chunk
    return bytes(out)


def pcd():
    n = len(CLOUD)
    put("pcd/points-ascii.pcd", pcd_header("x y z rgb", "4 4 4 4", "F F F F", "1 1 1 1", n, "ascii")
        + "".join("%g %g %g 4.2108e+06\n" % p for p in CLOUD))
    b = bytearray(pcd_header("x y z intensity", "4 4 4 2", "F F F U", "1 1 1 1", n, "binary").encode())
    for p in CLOUD:
        b += struct.pack("<3fH", *p, 9)
    put("pcd/points-binary.pcd", bytes(b))
    # binary_compressed: fields stored one after another (all x, then all y, ...), LZF-packed.
    raw = b"".join(struct.pack("<%df" % n, *(p[k] for p in CLOUD)) for k in range(3))
    raw += struct.pack("<%dd" % n, *(1.0 for _ in CLOUD))
    comp = lzf_literals(raw)
    head = pcd_header("x y z normal_x", "4 4 4 8", "F F F F", "1 1 1 1", n, "binary_compressed").encode()
    put("pcd/points-binary-compressed.pcd", head + struct.pack("<II", len(comp), len(raw)) + comp)
    put("pcd/organised-nan.pcd", "VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 2\n"
        "POINTS 4\nDATA ascii\n1 2 3\nnan nan nan\n4 5 6\n-1e3 2e-3 7\n")


def xyz():
    put("xyz/points.xyz", "# x y z [extra columns are ignored]\n" + "".join("%g %g %g 0.5 1\n" % p for p in CLOUD)
        + "\n// a comment line\n1e2,2e2,3e2\n")
    put("xyz/points-tabs.xyz", "".join("%g\t%g\t%g\r\n" % p for p in CLOUD))


for make in (stl, ply_mesh, off, gltf, dae, obj, ply_cloud, pcd, xyz):
    make()
