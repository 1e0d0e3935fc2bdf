#!/usr/bin/env python3
"""Writes the broken-file corpus of issue #17 into this folder (tests/data/corpus/).

Each file is a valid test file of the repository broken the way real files break: cut short,
emptied, with wrong counts, huge or negative indices, NaN and infinite numbers, another text
encoding (UTF-16, Latin-1, NUL bytes), or replaced by bytes of no format at all. The suite
(tests/io/test_corpus.cpp and the cli.check_corpus test) loads every file here and in
tests/data/fuzz/ and requires only radiosity::Error (exit 1 from `radiosity check`) or success:
never a crash, a foreign exception or a hang. The expected outcome of each file is not fixed,
only that it is one of those.

Deterministic: run it again and the same files come out. Run from anywhere:
    python3 tests/data/corpus/make_corpus.py
"""
import pathlib
import random
import struct

HERE = pathlib.Path(__file__).resolve().parent
DATA = HERE.parent
ROOT = DATA.parent.parent


def read(path):
    return (ROOT / path).read_bytes()


def write(name, data):
    (HERE / name).write_bytes(data)


def truncations(stem, ext, data):
    for percent in (10, 50, 90):
        write(f"{stem}_cut{percent}{ext}", data[: len(data) * percent // 100])


def main():
    for old in HERE.iterdir():
        if old.name != pathlib.Path(__file__).name and old.name != "README.md":
            old.unlink()
    rng = random.Random(17)

    # Every format: empty, and random bytes under its extension.
    for ext in (".obj", ".json", ".gltf", ".glb", ".vs3", ".ply", ".stl", ".exr", ".fbx", ".dae"):
        write(f"empty{ext}", b"")
        write(f"noise{ext}", bytes(rng.randrange(256) for _ in range(2048)))

    # OBJ (with its MTL).
    obj = read("tests/data/two_quads.obj")
    mtl = read("tests/data/two_quads.mtl")
    truncations("obj", ".obj", obj.replace(b"two_quads.mtl", b"obj_ok.mtl"))
    write("obj_ok.mtl", mtl)
    write("obj_huge_index.obj", obj.replace(b"f 5 6 7 8", b"f 5 6 7 2147483647"))
    write("obj_overflow_index.obj", obj.replace(b"f 5 6 7 8", b"f 5 6 7 99999999999999999999"))
    write("obj_negative_index.obj", obj.replace(b"f 5 6 7 8", b"f -1 -2 -3 -2147483648"))
    write("obj_nan.obj", obj.replace(b"v 1 0 0", b"v nan 0 0"))
    write("obj_inf.obj", obj.replace(b"v 1 0 0", b"v 1e999 0 0"))
    write("obj_hex_float.obj", obj.replace(b"v 1 0 0", b"v 0x1p3 0 0"))
    write("obj_utf16.obj", b"\xff\xfe" + obj.decode("ascii").encode("utf-16-le"))
    write("obj_latin1_names.obj", obj.replace(b"g floor", b"g B\xf6den \xe9t\xe9"))
    write("obj_nul_bytes.obj", obj.replace(b"v 1 1 0", b"v 1\x00 1 0"))
    write("obj_long_line.obj", obj + b"v " + b"1" * 100000 + b" 0 0\n")
    write("obj_no_newline.obj", obj.rstrip(b"\n"))
    write("obj_faces_only.obj", b"f 1 2 3\nf 4 5 6\n")
    write("obj_mtl_nan.obj", obj.replace(b"two_quads.mtl", b"obj_mtl_nan.mtl"))
    write("obj_mtl_nan.mtl", mtl.replace(b"Kd 0.8 0.7 0.6", b"Kd nan 0.7 -inf").replace(b"Ke 17 12 4", b"Ke 1e999 12"))
    write("obj_mtl_cut.obj", obj.replace(b"two_quads.mtl", b"obj_mtl_cut.mtl"))
    write("obj_mtl_cut.mtl", mtl[: len(mtl) // 2])
    write("obj_mtl_utf16.obj", obj.replace(b"two_quads.mtl", b"obj_mtl_utf16.mtl"))
    write("obj_mtl_utf16.mtl", b"\xff\xfe" + mtl.decode("ascii").encode("utf-16-le"))

    # JSON scenes.
    js = read("examples/scenes/cornell_box.json")
    truncations("json", ".json", js)
    text = js.decode("utf-8")
    write("json_huge_number.json", text.replace("0.725", "1e999", 1).encode())
    write("json_huge_vertex.json", text.replace("552.8", "1e999", 1).encode())
    write("json_nan_literal.json", text.replace("0.725", "NaN", 1).encode())
    write("json_tiny_vertex.json", text.replace("552.8", "-3.5e38", 1).encode())
    write("json_huge_version.json", text.replace('"version": 1', '"version": 18446744073709551616', 1).encode())
    write("json_utf16.json", b"\xff\xfe" + text.encode("utf-16-le"))
    write("json_latin1.json", text.replace('"', '"\xe9', 1).encode("latin-1", errors="replace"))
    write("json_nested.json", b"[" * 20000 + b"]" * 20000)
    write("json_wrong_types.json", b'{"materials": 3, "surfaces": "none"}')
    write("json_missing_obj.json", b'{"surfaces": [{"obj": "does_not_exist.obj"}]}')

    # glTF and GLB.
    gltf = read("tests/data/gltf/room.gltf")
    glb = read("tests/data/gltf/room.glb")
    truncations("gltf", ".gltf", gltf)
    truncations("glb", ".glb", glb)
    gtext = gltf.decode("utf-8")
    write("gltf_huge_count.gltf", gtext.replace('"count": 4', '"count": 4000000000', 1).encode())
    write("gltf_bad_view.gltf", gtext.replace('"bufferView": 0', '"bufferView": 99', 1).encode())
    write("gltf_negative_view.gltf", gtext.replace('"bufferView": 0', '"bufferView": -1', 1).encode())
    write("gltf_missing_buffer.gltf", b'{"asset": {"version": "2.0"}, "buffers": [{"uri": "nothing.bin", "byteLength": 64}]}')
    # GLB: the header's total length and the JSON chunk's length made larger than the file.
    write("glb_long_header.glb", glb[:8] + struct.pack("<I", 0x7FFFFFFF) + glb[12:])
    write("glb_long_chunk.glb", glb[:12] + struct.pack("<I", 0x7FFFFFF0) + glb[16:])
    write("glb_bad_magic.glb", b"glTX" + glb[4:])

    # View3D.
    vs3 = read("tests/data/view3d/cube.vs3")
    truncations("vs3", ".vs3", vs3)
    write("vs3_huge_index.vs3", vs3.replace(b"S  1    1   2   3   4", b"S  1    1   2   3   999999999"))
    write("vs3_nan.vs3", vs3.replace(b"V  2   2.", b"V  2   nan"))
    write("vs3_out_of_sequence.vs3", vs3.replace(b"V  3 ", b"V  9 "))
    write("vs3_utf16.vs3", b"\xff\xfe" + vs3.decode("ascii").encode("utf-16-le"))

    # PLY and STL (Assimp).
    ply = read("tests/data/facets.ply")
    truncations("ply", ".ply", ply)
    write("ply_huge_count.ply", ply.replace(b"element vertex 10", b"element vertex 4000000000"))
    write("ply_short_count.ply", ply.replace(b"element face 4", b"element face 40"))
    write("ply_huge_index.ply", ply.replace(b"\n3 0 1 2", b"\n3 0 1 2000000000", 1))
    stl = read("tests/data/facets_binary.stl")
    truncations("stl", ".stl", stl)
    write("stl_huge_count.stl", stl[:80] + struct.pack("<I", 0xFFFFFFFF) + stl[84:])
    write("stl_ascii_cut.stl", read("tests/data/facets.stl")[:200])

    # EXR (read_exr).
    exr = read("tests/data/half_partial.exr")
    truncations("exr", ".exr", exr)
    flipped = bytearray(exr)
    for i in range(8, len(flipped), 37):
        flipped[i] ^= 0x5A
    write("exr_flipped.exr", bytes(flipped))


if __name__ == "__main__":
    main()
