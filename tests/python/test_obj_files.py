"""OBJ + MTL files as exporters write them (Blender, 3ds Max, Maya, MeshLab, Windows tools): each
test checks mipraster.load_scene against an independent oracle: an equivalent plain file, a
hand-built scene, the numbers written into the file, or exact polygon coverage."""
import warnings

import numpy as np
import pytest
from PIL import Image

import mipraster as mr

# The 2x2 test texture, linear RGBA: red, green / blue, white (every value exact in sRGB8).
TEXELS = np.float32([[[1, 0, 0, 1], [0, 1, 0, 1]], [[0, 0, 1, 1], [1, 1, 1, 1]]])
# A quad filling [-1, 1]^2 at z = 0, seen exactly by CAMERA; vt (0, 0) at its bottom-left corner.
QUAD_V = np.float64([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]])
QUAD_VT = np.float64([[0, 0], [1, 0], [1, 1], [0, 1]])
CAMERA = mr.Camera.orthographic((0, 0, 5), (0, 0, 0), height=2.0, near=0.1, far=10)


def obj_text(vt=QUAD_VT, material="tex", mtllib="m.mtl"):
    lines = [f"mtllib {mtllib}"] + [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in QUAD_V]
    lines += [f"vt {float(u)!r} {float(v)!r}" for u, v in vt] + [f"usemtl {material}", "f 1/1 2/2 3/3 4/4", ""]
    return "\n".join(lines)


def load_quiet(path):
    """load_scene, returning the warnings' messages too."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene, cameras = mr.load_scene(path)
    assert cameras == []
    return scene, [str(w.message) for w in caught]


def render(scene, size=32):
    return mr.render(scene, CAMERA, size, size).color


# --- map_Kd options --------------------------------------------------------------------------


@pytest.mark.parametrize("options, scale, offset", [
    ("-s 2 2 1 -o 0.25 0 0", (2, 2), (0.25, 0)),
    ("-s 2 3 -o 0.25 0.5", (2, 3), (0.25, 0.5)),   # v and w are optional (tinyobjloader took the file name as w)
    ("-o 0.125", (1, 1), (0.125, 0)),
    ("-bm 0.5 -blendu off -blendv off -boost 2 -texres 512 -imfchan r -s 3 1 1", (3, 1), (0, 0)),
])
def test_map_kd_scale_and_offset_render_like_transformed_vt(tmp_path, options, scale, offset):
    # Oracle: the same quad with vt·s + o written by numpy and no options: bit-identical renders.
    mr.write_image(tmp_path / "checker.png", TEXELS)
    (tmp_path / "m.mtl").write_text(f"newmtl tex\nKd 1 1 1\nmap_Kd {options} checker.png\n"
                                    "newmtl plain\nKd 1 1 1\nmap_Kd checker.png\n")
    (tmp_path / "opts.obj").write_text(obj_text())
    (tmp_path / "moved.obj").write_text(obj_text(QUAD_VT * np.float64(scale) + np.float64(offset), "plain"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # options without a look of their own are skipped quietly
        with_options, _ = mr.load_scene(tmp_path / "opts.obj")
    moved, _ = mr.load_scene(tmp_path / "moved.obj")
    assert with_options.draws[0].texture.name == moved.draws[0].texture.name
    np.testing.assert_array_equal(with_options.draws[0].mesh.uvs, moved.draws[0].mesh.uvs)
    np.testing.assert_array_equal(render(with_options), render(moved))


def test_map_kd_options_stay_with_their_material(tmp_path):
    # Two materials on faces sharing every vertex and vt: only the scaled one's uvs change.
    mr.write_image(tmp_path / "checker.png", TEXELS)
    (tmp_path / "m.mtl").write_text("newmtl a\nmap_Kd -s 2 2 1 checker.png\nnewmtl b\nmap_Kd checker.png\n")
    path = tmp_path / "two.obj"
    path.write_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.25 0.5\nvt 0.5 0.5\nvt 0.25 1\n"
                    "usemtl a\nf 1/1 2/2 3/3\nusemtl b\nf 1/1 2/2 3/3\nusemtl a\nf 1/1 3/3 2/2\n")
    scene, _ = mr.load_scene(path)
    a, b = scene.draws
    np.testing.assert_array_equal(a.mesh.uvs, [[0.5, 0.0], [1.0, 0.0], [0.5, -1.0]])  # 1 − 2v flips v
    np.testing.assert_array_equal(b.mesh.uvs, [[0.25, 0.5], [0.5, 0.5], [0.25, 0.0]])


@pytest.mark.parametrize("options, ignored", [("-mm 0.2 0.5", "-mm"), ("-t 0.1 0.1 0", "-t"), ("-cc on", "-cc"),
                                              ("-halo 1", "'-halo' is unknown")])
def test_map_kd_options_that_are_not_applied_warn_and_keep_the_file(tmp_path, options, ignored):
    mr.write_image(tmp_path / "checker.png", TEXELS)
    (tmp_path / "m.mtl").write_text(f"newmtl tex\nmap_Kd {options} checker.png\n")
    (tmp_path / "s.obj").write_text(obj_text())
    scene, messages = load_quiet(tmp_path / "s.obj")
    assert scene.draws[0].texture.name == str(tmp_path / "checker.png")
    assert any("m.mtl: line 2: material 'tex'" in m and ignored in m for m in messages), messages


# --- texture paths ---------------------------------------------------------------------------


@pytest.mark.parametrize("written, on_disk, warns", [
    ("textures\\wood.png", "textures/wood.png", False),          # Windows separators
    ("my wood.png", "my wood.png", False),                       # spaces
    ("C:\\Users\\bob\\Desktop\\wood.png", "wood.png", True),     # another machine's absolute path
    ("/home/bob/project/textures/wood.png", "wood.png", True),
    ("Textures\\Wood.PNG", "textures/wood.png", True),           # case from Windows
    ("wood.png", "mats/wood.png", False),                        # next to the MTL file (mtllib mats/m.mtl)
])
def test_texture_paths_from_other_systems_are_found(tmp_path, written, on_disk, warns):
    in_mats = on_disk.startswith("mats/")
    (tmp_path / on_disk).parent.mkdir(parents=True, exist_ok=True)
    mr.write_image(tmp_path / on_disk, TEXELS)
    (tmp_path / "mats").mkdir(exist_ok=True)
    mtl = tmp_path / ("mats/m.mtl" if in_mats else "m.mtl")
    mtl.write_text(f"newmtl tex\nKd 1 1 1\nmap_Kd {written}\n")
    (tmp_path / "s.obj").write_text(obj_text(mtllib="mats/m.mtl" if in_mats else "m.mtl"))
    scene, messages = load_quiet(tmp_path / "s.obj")
    (d,) = scene.draws
    assert d.texture.name == str(tmp_path / on_disk)
    np.testing.assert_allclose(d.texture.level(0), TEXELS, atol=1e-6)
    about_map = [m for m in messages if "map_Kd" in m]
    if warns:  # found elsewhere than written: say where
        assert len(about_map) == 1, messages
        assert about_map[0].startswith(f"{mtl}: material 'tex': map_Kd '{written}' is not at ")
        assert about_map[0].endswith(f"; using '{tmp_path / on_disk}'")
    else:
        assert about_map == []


# --- materials -------------------------------------------------------------------------------


@pytest.mark.parametrize("mtllib, files", [
    ("a.mtl b.mtl", {"a.mtl": "newmtl red\nKd 1 0 0\n", "b.mtl": "newmtl blue\nKd 0 0 1\n"}),
    ("my materials.mtl", {"my materials.mtl": "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n"}),
    ("mats\\m.mtl", {"mats/m.mtl": "newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n"}),
    ("m.mtl", {"m.mtl": "newmtl 01 - Default\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n"}),  # 3ds Max's default name
])
def test_mtllib_forms_find_every_material(tmp_path, mtllib, files):
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(exist_ok=True)
        (tmp_path / name).write_text(text)
    red = "01 - Default" if "01 - Default" in str(files) else "red"
    path = tmp_path / "s.obj"
    path.write_text(f"mtllib {mtllib}\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl {red}\nf 1 2 3\nusemtl blue\nf 1 3 2\n")
    scene, messages = load_quiet(path)
    assert messages == []
    assert [d.color for d in scene.draws] == [(1, 0, 0, 1), (0, 0, 1, 1)]


def test_missing_materials_warn_with_their_line_and_draw_white(tmp_path):
    (tmp_path / "m.mtl").write_text("newmtl red\nKd 1 0 0\n")
    path = tmp_path / "s.obj"
    path.write_text("mtllib m.mtl gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl blue\nf 1 2 3\n")
    scene, messages = load_quiet(path)
    assert scene.draws[0].color == (1, 1, 1, 1)
    missing = f"{path}: line 1: MTL file 'gone.mtl' not found next to the OBJ file; its materials are drawn white"
    assert missing in messages
    assert f"{path}: line 5: usemtl 'blue' names no material of its MTL files; drawn white" in messages


def test_material_without_kd_is_white(tmp_path):
    # tinyobjloader's default: black, or 0.6 grey when the material has a map_Kd. The texture
    # shows as it is (Kd multiplies it).
    mr.write_image(tmp_path / "checker.png", TEXELS)
    (tmp_path / "m.mtl").write_text("newmtl tex\nNs 10\nmap_Kd checker.png\nnewmtl plain\nillum 2\n")
    (tmp_path / "s.obj").write_text(obj_text() + "v 5 5 0\nv 6 5 0\nv 5 6 0\nusemtl plain\nf 5 6 7\n")  # out of view
    scene, _ = mr.load_scene(tmp_path / "s.obj")
    assert [d.color for d in scene.draws] == [(1, 1, 1, 1), (1, 1, 1, 1)]
    np.testing.assert_allclose(render(scene, 2), TEXELS, atol=1e-6)  # one pixel per texel centre


def dissolve_oracle(alpha):
    """A hand-built scene: an opaque blue quad at z = 0, then a red one at z = 0.5 blended over it
    with the colour premultiplied by alpha (glTF alphaMode BLEND)."""
    scene = mr.Scene()
    scene.add(mr.Mesh(QUAD_V, [[0, 1, 2], [0, 2, 3]]), color=(0, 0, 1, 1))
    scene.add(mr.Mesh(QUAD_V + [0, 0, 0.5], [[0, 1, 2], [0, 2, 3]]), color=(alpha, 0, 0, alpha),
              blend="replace" if alpha == 1 else "over")
    return scene


@pytest.mark.parametrize("statements, alpha, note", [
    ("d 0.25", 0.25, None),
    ("Tr 0.75", 0.25, None),
    ("d 1\nTr 0", 1.0, None),                      # 3ds Max writes both: no warning
    ("d 0.25\nTr 0.25", 0.25, "disagree"),
    ("d -halo 0.25", 0.25, "-halo"),
    ("d 1.5", 1.0, "outside [0, 1]"),
])
def test_dissolve_blends_over_like_gltf_blend(tmp_path, statements, alpha, note):
    (tmp_path / "m.mtl").write_text(f"newmtl blue\nKd 0 0 1\nnewmtl glass\nKd 1 0 0\n{statements}\n")
    path = tmp_path / "s.obj"
    path.write_text("mtllib m.mtl\n" + "".join(f"v {x} {y} 0\n" for x, y, _ in QUAD_V)
                    + "".join(f"v {x} {y} 0.5\n" for x, y, _ in QUAD_V)
                    + "usemtl blue\nf 1 2 3 4\nusemtl glass\nf 5 6 7 8\n")
    scene, messages = load_quiet(path)
    assert scene.draws[1].blend == ("replace" if alpha == 1.0 else "over")
    np.testing.assert_array_equal(render(scene, 8), render(dissolve_oracle(alpha), 8))
    if note is None:
        assert messages == []
    else:
        assert len(messages) == 1 and "material 'glass'" in messages[0] and note in messages[0], messages


@pytest.mark.parametrize("dissolve", [1.0, 0.5])
def test_map_kd_alpha_counts_only_when_the_material_blends(tmp_path, dissolve):
    # As glTF: an opaque material ignores its texture's alpha, a blended one multiplies it in.
    texels = TEXELS.copy()
    texels[0, 1] = [0, 0.2, 0, 0.2]  # premultiplied: green at alpha 0.2
    mr.write_image(tmp_path / "cutout.png", texels)
    (tmp_path / "m.mtl").write_text(f"newmtl tex\nd {dissolve}\nmap_Kd cutout.png\n")
    (tmp_path / "s.obj").write_text(obj_text())
    scene, _ = mr.load_scene(tmp_path / "s.obj")
    alpha = scene.draws[0].texture.level(0)[..., 3]
    np.testing.assert_allclose(alpha, texels[..., 3] if dissolve < 1 else 1.0, atol=1e-6)
    np.testing.assert_allclose(render(scene, 2)[0, 1, 3], 0.2 * dissolve if dissolve < 1 else 1.0, atol=1e-6)


# --- map_d alpha masks ------------------------------------------------------------------------

BEHIND = np.float32([0.1, 0.2, 0.3, 1.0])
# The mask of the quadrants TL, TR / BL, BR: kept, discarded / discarded (0.4 < 0.5), kept.
MASK = np.float32([[1.0, 0.0], [0.4, 0.8]])


def masked_obj(tmp_path, statements):
    """The textured quad with material `statements` (map_Kd checker.png and maybe a map_d), loaded,
    then an opaque quad behind it (drawn after it: it shows only where no depth was written)."""
    mr.write_image(tmp_path / "checker.png", TEXELS)
    (tmp_path / "m.mtl").write_text(f"newmtl tex\nKd 1 1 1\n{statements}\n")
    (tmp_path / "s.obj").write_text(obj_text())
    scene, messages = load_quiet(tmp_path / "s.obj")
    scene.add(mr.Mesh(QUAD_V - [0, 0, 1], [[0, 1, 2], [0, 2, 3]]), color=BEHIND)
    return scene, messages


def quadrants(color):
    h, w = color.shape[:2]
    return np.array([color[h // 4, w // 4], color[h // 4, 3 * w // 4], color[3 * h // 4, w // 4],
                     color[3 * h // 4, 3 * w // 4]])


def expect_masked(color, mask):
    """TEXELS (opaque) where the mask is at least 0.5, BEHIND elsewhere (a 2x2 render: pixel centres on
    texel centres, where the default trilinear filter returns the texels)."""
    for q, (texel, m) in enumerate(zip(TEXELS.reshape(4, 4), mask.reshape(4))):
        np.testing.assert_allclose(quadrants(color)[q], texel if m >= 0.5 else BEHIND, atol=1e-6,
                                   err_msg=f"quadrant {q}")


@pytest.mark.parametrize("mask_size", [2, 3, 4])
def test_map_d_grey_mask_alpha_tests_the_texture(tmp_path, mask_size):
    # A grey mask file (read as data, code / 255), of the texture's size or another: each texel of the
    # texture takes the mask texel its centre falls in (nearest); the others hold 0.6, which a wrong
    # pick would show.
    index = np.floor((np.arange(2) + 0.5) / 2 * mask_size).astype(int)
    mask = np.full((mask_size, mask_size), 0.6, np.float32)
    mask[np.ix_(index, index)] = MASK
    Image.fromarray(np.round(mask * 255).astype(np.uint8), "L").save(tmp_path / "mask.png")
    scene, messages = masked_obj(tmp_path, "map_Kd checker.png\nmap_d mask.png")
    assert messages == []
    d = scene.draws[0]
    assert d.alpha_cutoff == 0.5 and d.blend == "replace"
    np.testing.assert_allclose(d.texture.level(0)[..., 3], np.round(MASK * 255) / 255, atol=1e-6)
    expect_masked(render(scene, 2), MASK)


def test_map_d_naming_the_map_kd_file_uses_its_alpha(tmp_path):
    texels = TEXELS * MASK[..., None]  # premultiplied by the mask
    mr.write_image(tmp_path / "cutout.png", texels)
    scene, messages = masked_obj(tmp_path, "map_Kd cutout.png\nmap_d cutout.png")
    assert messages == [] and scene.draws[0].alpha_cutoff == 0.5
    color = render(scene, 2)  # (pixel centres on texel centres: the filter returns the texels)
    for q, m in enumerate(MASK.reshape(4)):
        if m < 0.5:
            np.testing.assert_array_equal(quadrants(color)[q], BEHIND)
        else:  # the straight colour, opaque (8-bit sRGB: within a step of TEXELS)
            np.testing.assert_allclose(quadrants(color)[q], TEXELS.reshape(4, 4)[q], atol=1e-2)


def test_map_d_under_a_dissolve_blends_instead(tmp_path):
    Image.fromarray(np.round(MASK * 255).astype(np.uint8), "L").save(tmp_path / "mask.png")
    scene, _ = masked_obj(tmp_path, "d 0.5\nmap_Kd checker.png\nmap_d mask.png")
    d = scene.draws[0]
    assert d.alpha_cutoff is None and d.blend == "over"
    np.testing.assert_allclose(d.texture.level(0)[..., 3], np.round(MASK * 255) / 255, atol=1e-6)


@pytest.mark.parametrize("statements, note", [
    ("map_Kd checker.png\nmap_d missing.png", "missing.png': no such file); drawn without it"),
    ("map_d missing.png", "missing.png': no such file); drawn without it"),
    ("map_Kd checker.png\nmap_d", "map_d names no file"),
])
def test_map_d_that_cannot_be_used_warns_and_draws_without_it(tmp_path, statements, note):
    Image.fromarray(np.round(MASK * 255).astype(np.uint8), "L").save(tmp_path / "mask.png")
    scene, messages = masked_obj(tmp_path, statements)
    assert len(messages) == 1 and note in messages[0] and "material 'tex'" in messages[0], messages
    assert scene.draws[0].alpha_cutoff is None
    color = render(scene, 2)
    assert not np.any(np.all(color == BEHIND, axis=-1))  # no holes


# Placement options of a map and the columns of a 2x2 image that the 2x2 render's pixel columns then
# read: -o 0.5 swaps them (u + 0.5, repeated); with -clamp on both read the right one (u 0.75 and
# 1.25, clamped).
PLACEMENTS = [("", [0, 1]), ("-o 0.5 0 ", [1, 0]), ("-clamp on -o 0.5 0 ", [1, 1])]


@pytest.mark.parametrize("options, columns", PLACEMENTS)
def test_map_d_without_map_kd_masks_the_kd_colour(tmp_path, options, columns):
    # A mask alone, placed by its own options: the material's Kd where the mask keeps the quad (a white
    # texture times Kd, opaque), what lies behind elsewhere.
    Image.fromarray(np.round(MASK * 255).astype(np.uint8), "L").save(tmp_path / "mask.png")
    (tmp_path / "m.mtl").write_text(f"newmtl tex\nKd 0.2 0.6 0.9\nmap_d {options}mask.png\n")
    (tmp_path / "s.obj").write_text(obj_text())
    scene, messages = load_quiet(tmp_path / "s.obj")
    scene.add(mr.Mesh(QUAD_V - [0, 0, 1], [[0, 1, 2], [0, 2, 3]]), color=BEHIND)
    assert messages == []
    d = scene.draws[0]
    assert d.alpha_cutoff == 0.5 and d.blend == "replace"
    np.testing.assert_allclose(d.texture.level(0)[..., 3], np.round(MASK * 255) / 255, atol=1e-6)
    kd = np.float32([0.2, 0.6, 0.9, 1.0])
    for q, m in enumerate(MASK[:, columns].reshape(4)):
        np.testing.assert_allclose(quadrants(render(scene, 2))[q], kd if m >= 0.5 else BEHIND, atol=1e-6,
                                   err_msg=f"quadrant {q}")


@pytest.mark.parametrize("options, columns", PLACEMENTS)
def test_map_d_placed_as_map_kd_moves_with_it(tmp_path, options, columns):
    # map_Kd and map_d with the same placement (as exporters write them): texture and mask move together.
    Image.fromarray(np.round(MASK * 255).astype(np.uint8), "L").save(tmp_path / "mask.png")
    scene, messages = masked_obj(tmp_path, f"map_Kd {options}checker.png\nmap_d {options}mask.png")
    assert messages == []
    color = render(scene, 2)
    for q, (texel, m) in enumerate(zip(TEXELS[:, columns].reshape(4, 4), MASK[:, columns].reshape(4))):
        np.testing.assert_allclose(quadrants(color)[q], texel if m >= 0.5 else BEHIND, atol=1e-6,
                                   err_msg=f"quadrant {q}")


def test_map_d_options_that_would_move_the_mask_off_map_kd_warn(tmp_path):
    Image.fromarray(np.round(MASK * 255).astype(np.uint8), "L").save(tmp_path / "mask.png")
    scene, messages = masked_obj(tmp_path, "map_Kd checker.png\nmap_d -imfchan l -s 2 2 1 mask.png")
    assert len(messages) == 1 and "map_d's -s, -o or -clamp differ from map_Kd's" in messages[0], messages
    expect_masked(render(scene, 2), MASK)


def test_map_d_options_that_change_the_look_warn(tmp_path):
    Image.fromarray(np.round(MASK * 255).astype(np.uint8), "L").save(tmp_path / "mask.png")
    scene, messages = masked_obj(tmp_path, "map_Kd checker.png\nmap_d -mm 0.2 1 -t 0 0 0 mask.png")
    assert len(messages) == 1 and "map_d option -mm is not supported" in messages[0], messages
    expect_masked(render(scene, 2), MASK)


# --- text forms ------------------------------------------------------------------------------

PLAIN = "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n"


@pytest.mark.parametrize("name, text", [
    ("byte order mark", b"\xef\xbb\xbf" + PLAIN.encode()),
    ("CRLF", PLAIN.replace("\n", "\r\n").encode()),
    ("classic Mac CR", PLAIN.replace("\n", "\r").encode()),
    ("tabs and indentation", PLAIN.replace(" ", "\t").replace("\nv", "\n  v").encode()),
    ("comments", ("# exported\n" + PLAIN.replace("\nf", " # normal\nf").rstrip("\n") + " # quad\n").encode()),
    ("line continuation", PLAIN.replace("2/2/1 ", "2/2/1 \\\n  ").replace("v 2 0 0", "v 2 \\\n0 0").encode()),
    ("relative indices", PLAIN.replace("f 1/1/1 2/2/1 3/3/1 4/4/1", "f -4/-4/-1 -3/-3/-1 -2/-2/-1 -1/-1/-1").encode()),
    ("objects, groups, smoothing, lines", ("o cube\ng side top\ns 1\n" + PLAIN + "s off\nl 1 2\np 3\n").encode()),
])
def test_text_forms_load_like_the_plain_file(tmp_path, name, text):
    (tmp_path / "plain.obj").write_text(PLAIN)
    (tmp_path / "form.obj").write_bytes(text)
    expected, _ = mr.load_scene(tmp_path / "plain.obj")
    got, messages = load_quiet(tmp_path / "form.obj")
    assert len(got.draws) == 1, name
    for attr in ("positions", "triangles", "uvs", "normals"):
        np.testing.assert_array_equal(getattr(got.draws[0].mesh, attr), getattr(expected.draws[0].mesh, attr))
    assert messages == ([f"{tmp_path / 'form.obj'}: 2 line (l) or point (p) element(s) not drawn"]
                        if name.endswith("lines") else [])


@pytest.mark.parametrize("text, message", [
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 9\n", r"line 4: vertex index 9 out of range \(the file has 3\)"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 1/2\n",
     r"line 5: texture coordinate index 2 out of range \(the file has 1\)"),
    ("v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", r"line 3 \('f -1 -2 -3'\): vertex index -3 reaches before the first"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", r"line 4 \('f 0 1 2'\): index 0 in '0'"),
    ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", r"line 4 .*'1/1/1/1' is not a face corner"),
])
def test_bad_face_indices_are_errors_naming_file_and_line(tmp_path, text, message):
    # tinyobjloader dropped a quad with an index out of range (a warning without its line), and
    # read a relative index before the first vertex as "vertex index 0".
    path = tmp_path / "bad.obj"
    path.write_text(text)
    with pytest.raises(OSError, match=rf"bad\.obj: {message}"):
        mr.load_scene(path)


@pytest.mark.parametrize("line, message", [
    ("v -1", r"a vertex needs 3 coordinates \(x y z\), got 1"),
    ("v", r"a vertex needs 3 coordinates \(x y z\), got 0"),
    ("v 0 0", r"a vertex needs 3 coordinates \(x y z\), got 2"),
    ("v 0 0 0 1 0", r"a vertex is x y z, x y z w or x y z r g b \(with a colour\), got 5 numbers"),
    ("v 0 0 0 1 0 0 1", r"a vertex is x y z, x y z w or x y z r g b \(with a colour\), got 7 numbers"),
    ("vn 1", r"a normal needs 3 coordinates \(i j k\), got 1"),
    ("vn 0 0 1 0", r"a normal needs 3 coordinates \(i j k\), got 4"),
    ("vt", r"a texture coordinate is u \[v \[w\]\] \(1 to 3 numbers\), got 0"),
    ("vt 0 0 0 0", r"a texture coordinate is u \[v \[w\]\] \(1 to 3 numbers\), got 4"),
])
def test_vertex_lines_with_a_wrong_count_of_numbers_are_errors_naming_the_line(tmp_path, line, message):
    # tinyobjloader filled missing numbers with 0 and dropped extra ones: 'v -1' loaded as (-1, 0, 0),
    # a bare 'v' was not counted (the faces after it took the wrong vertices).
    path = tmp_path / "short.obj"
    path.write_text(f"v -1 -1 0\nv 1 -1 0\nv 0 1 0\n{line}\nf 1 2 3\n")
    with pytest.raises(OSError, match=rf"short\.obj: line 4 \('{line}'\): {message}"):
        mr.load_scene(path)


def test_vertex_lines_of_every_legal_length_load(tmp_path):
    # v x y z w (w ignored); vt u (v = 0, as the OBJ spec has it) and vt u v w (w ignored).
    path = tmp_path / "forms.obj"
    path.write_text("v -1 -1 0 1\nv 1 -1 0 0.5\nv 0 1 0\nvt 0.25\nvt 0.5 0.75 0\nvn 0 0 1\n"
                    "f 1/1/1 2/2/1 3/1/1\n")
    scene, messages = load_quiet(path)
    assert messages == []
    mesh = scene.draws[0].mesh
    np.testing.assert_array_equal(mesh.positions, QUAD_V[[0, 1]].tolist() + [[0, 1, 0]])
    np.testing.assert_array_equal(mesh.uvs, [[0.25, 1.0], [0.5, 0.25], [0.25, 1.0]])  # 1 − v flips v
    np.testing.assert_array_equal(mesh.normals, [[0, 0, 1]] * 3)


def test_vertex_colours_outside_0_1_warn_naming_the_first_line(tmp_path):
    # The 0-255 convention some exporters use was drawn as colour 255, without a word.
    path = tmp_path / "colours.obj"
    path.write_text("v -1 -1 0 0 0 1\nv 1 -1 0 255 0 0\nv 0 1 0 0 128 0\nf 1 2 3\n")
    scene, messages = load_quiet(path)
    assert messages == [f"{path}: line 2: vertex colour 255 is outside [0, 1] (2 value(s) in all); colours are "
                        "expected in [0, 1] (0-255 ones are not rescaled), they are drawn as written"]
    np.testing.assert_array_equal(scene.draws[0].mesh.colors, [[0, 0, 1, 1], [255, 0, 0, 1], [0, 128, 0, 1]])
    path.write_text("v -1 -1 0 0 0 1\nv 1 -1 0 1 0 0\nv 0 1 0 0 0.5 0\nf 1 2 3\n")
    assert load_quiet(path)[1] == []


@pytest.mark.parametrize("kd", ["1e39 0 0", "0.5", "0 0 -4e38"])
def test_kd_beyond_float_is_an_error_naming_the_mtl_line(tmp_path, kd):
    # (finite as a double, inf as the draw's float colour: the render refused "draws[0].color")
    (tmp_path / "m.mtl").write_text(f"newmtl tex\nKd {kd}\n")
    (tmp_path / "s.obj").write_text(obj_text())
    if kd == "0.5":
        scene, _ = mr.load_scene(tmp_path / "s.obj")
        assert scene.draws[0].color == (0.5, 0.5, 0.5, 1)
        return
    with pytest.raises(OSError, match=rf"m\.mtl: line 2 \('Kd {kd}'\): Kd's numbers are beyond float's range"):
        mr.load_scene(tmp_path / "s.obj")


def test_map_kd_naming_a_device_warns_and_draws_the_error_texture(tmp_path):
    # /dev/zero as a texture: OpenImageIO searched its endless bytes for a header and never returned.
    (tmp_path / "m.mtl").write_text("newmtl tex\nmap_Kd /dev/zero\n")
    (tmp_path / "s.obj").write_text(obj_text())
    scene, messages = load_quiet(tmp_path / "s.obj")
    assert scene.draws[0].texture.name == "error texture"
    assert any("'/dev/zero'" in m and "not a regular file" in m for m in messages), messages


# --- polygons --------------------------------------------------------------------------------


def star(n, inner=0.45, turn=0.1):
    a = np.linspace(0, 2 * np.pi, 2 * n, endpoint=False) + turn
    r = np.where(np.arange(2 * n) % 2 == 0, 0.9, inner)
    return np.stack([r * np.cos(a), r * np.sin(a)], -1)


POLYGONS = {
    # The shorter diagonal (corners 1-3) lies outside: tinyobjloader split along it, covering the
    # notch (triangle 1-3-4, outside the quad) twice.
    "dart quad": [(-0.91, -0.23), (0.93, 0.02), (-0.89, 0.21), (-0.69, 0.01)],
    "L, notch first": [(0.87, 0.03), (0.03, 0.03), (0.03, 0.91), (-0.89, 0.91), (-0.89, -0.93), (0.87, -0.93)],
    "star": star(5),
    "star of 300 corners": star(150, inner=0.7),  # beyond tinyobjloader's 255 corners per face
    "convex pentagon": [(-0.8, -0.7), (0.7, -0.8), (0.9, 0.3), (0.05, 0.92), (-0.85, 0.4)],
}


def inside(polygon, x, y):
    """Even-odd point-in-polygon test, the oracle for coverage."""
    result = np.zeros(x.shape, bool)
    for (x0, y0), (x1, y1) in zip(polygon, np.roll(polygon, -1, axis=0)):
        crosses = (y0 > y) != (y1 > y)
        with np.errstate(divide="ignore", invalid="ignore"):
            result ^= crosses & (x < x0 + (y - y0) * (x1 - x0) / (y1 - y0))
    return result


def near_an_edge(polygon, x, y, distance):
    """Points within `distance` of the polygon's boundary (vertex snapping may move them across)."""
    near = np.zeros(x.shape, bool)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0)):
        t = np.clip(((x - a[0]) * (b[0] - a[0]) + (y - a[1]) * (b[1] - a[1])) / np.sum((b - a) ** 2), 0, 1)
        near |= np.hypot(x - a[0] - t * (b[0] - a[0]), y - a[1] - t * (b[1] - a[1])) < distance
    return near


def signed_area(p):
    return 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])


@pytest.mark.parametrize("name", POLYGONS)
@pytest.mark.parametrize("reverse", [False, True])
def test_polygons_cover_exactly_their_inside(tmp_path, name, reverse):
    polygon = np.asarray(POLYGONS[name], dtype=np.float64)
    if reverse:
        polygon = polygon[::-1]
    path = tmp_path / "polygon.obj"
    path.write_text("".join(f"v {float(x)!r} {float(y)!r} 0\n" for x, y in polygon)
                    + "f " + " ".join(str(i + 1) for i in range(len(polygon))) + "\n")
    scene, messages = load_quiet(path)
    assert messages == []
    mesh = scene.draws[0].mesh
    # The triangles tile the polygon: n − 2 of them, each wound like it, their areas adding up to its.
    assert len(mesh.triangles) == len(polygon) - 2
    areas = [signed_area(mesh.positions[t, :2].astype(np.float64)) for t in mesh.triangles]
    whole = signed_area(polygon)
    assert all(np.sign(a) == np.sign(whole) for a in areas), areas
    assert sum(areas) == pytest.approx(whole, rel=1e-6)
    # And a render covers exactly the pixels whose centres are inside.
    size = 96
    alpha = mr.render(scene, CAMERA, size, size).color[..., 3]
    centres = (np.arange(size) + 0.5) / size * 2 - 1
    x, y = np.meshgrid(centres, -centres)
    differ = ((alpha > 0) != inside(polygon, x, y)) & ~near_an_edge(polygon, x, y, 0.01 * 2 / size)
    assert not differ.any(), f"{differ.sum()} pixels differ"


def test_a_polygon_beyond_the_ear_clipping_limit_is_fanned_with_a_warning(tmp_path):
    # Ear clipping can take n³ steps: a hostile face of 10⁵ corners would not finish. Past 1024
    # corners a polygon is fanned: exact for a convex one (here a 4000-gon), with a warning.
    a = np.linspace(0, 2 * np.pi, 4000, endpoint=False)
    polygon = np.stack([0.9 * np.cos(a), 0.9 * np.sin(a)], -1)
    path = tmp_path / "circle.obj"
    path.write_text("".join(f"v {float(x)!r} {float(y)!r} 0\n" for x, y in polygon)
                    + "f " + " ".join(str(i + 1) for i in range(len(polygon))) + "\n")
    scene, messages = load_quiet(path)
    assert any("more than 1024 corners; triangulated as fans" in m for m in messages), messages
    mesh = scene.draws[0].mesh
    assert len(mesh.triangles) == len(polygon) - 2
    assert (mesh.triangles[:, 0] == mesh.triangles[0, 0]).all()  # one fan around one corner
    areas = [signed_area(mesh.positions[t, :2].astype(np.float64)) for t in mesh.triangles]
    assert all(area > 0 for area in areas)
    assert sum(areas) == pytest.approx(signed_area(polygon), rel=1e-6)
