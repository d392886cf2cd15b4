"""Random scenes at extreme scales render finite colours within the range their inputs allow.

Each case draws a few random triangles (vertex colours and uvs in [0, 1), a texture in [0, 1) with
alpha 1) at a random scale from 1e-30 to 1e37, sometimes with one vertex far off, through a
look-at, orthographic or raw perspective camera whose matrix is scaled by up to 1e120 (the same
camera), with every texture filter and wrap mode. Whatever the geometry, a sample's colour is a
convex blend of such values, so the image is finite, non-negative and has alpha ≤ 1; rgb is at
most 1 with replace blending, and with "over" at most the number of triangles (the colours are
not premultiplied, so each layer can add up to 1). The oracle is that bound. On the code
before 1/w was scaled per triangle (a projection times 1e46 gave 1/w = 0 in float), 39 of these
cases rendered NaN.
"""
import numpy as np

import mipraster as mr

FILTERS = ["nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"]
WRAPS = ["repeat", "clamp", "mirror", "border"]


def _positions(rng, count):
    scale = 10.0 ** rng.uniform(-30, 37)
    kind = rng.integers(0, 3)
    if kind == 0:
        pos = rng.normal(size=(count, 3)) * scale
    elif kind == 1:  # one vertex far off (often behind the eye)
        pos = rng.normal(size=(count, 3))
        pos[rng.integers(0, count)] *= 10.0 ** rng.uniform(5, 37)
    else:  # each coordinate of its own magnitude and sign
        pos = rng.choice([-1.0, 1.0], size=(count, 3)) * 10.0 ** rng.uniform(-40, 38, size=(count, 3))
    return np.clip(pos, -3e38, 3e38).astype(np.float32)


def _camera(rng):
    kind = rng.integers(0, 3)
    if kind == 0:
        eye = rng.normal(size=3) * 10.0 ** rng.uniform(-20, 10)
        direction = rng.normal(size=3) * 10.0 ** rng.uniform(-10, 10) * (1.0 + np.abs(eye).max())
        return mr.Camera.look_at(tuple(eye), tuple(eye + direction))
    if kind == 1:
        eye = rng.normal(size=3) * 10.0 ** rng.uniform(-10, 10)
        return mr.Camera.orthographic(tuple(eye), tuple(eye + rng.normal(size=3)),
                                      height=float(10.0 ** rng.uniform(-20, 30)),
                                      near=-float(10.0 ** rng.uniform(-5, 30)), far=float(10.0 ** rng.uniform(-5, 30)))
    perspective = np.array([[1.5, 0, 0, 0], [0, 1.5, 0, 0], [0, 0, 0, 0.1], [0, 0, -1, 0]])  # reverse-Z, near 0.1
    return mr.Camera.from_matrices(np.eye(4), perspective * 10.0 ** rng.uniform(-60, 120), depth_convention="reverse_z")


def test_random_extreme_scenes_render_finite_colours_within_the_inputs_range():
    rng = np.random.default_rng(20261127)
    texels = rng.random((16, 16, 4)).astype(np.float32)
    texels[..., 3] = 1.0
    texture = mr.Texture(texels)
    failures, drawn = [], 0
    for case in range(3000):
        count = int(rng.integers(3, 9))
        triangles = rng.integers(0, count, size=(int(rng.integers(1, 6)), 3))
        mesh = mr.Mesh(_positions(rng, count), triangles,
                       colors=rng.random((count, 4)).astype(np.float32), uvs=rng.random((count, 2)).astype(np.float32))
        blend = str(rng.choice(["replace", "over"]))
        scene = mr.Scene()
        options = dict(cull="none", blend=blend, interpolation=str(rng.choice(["perspective", "screen", "flat"])))
        if rng.random() < 0.6:
            sampler = mr.Sampler(filter=str(rng.choice(FILTERS)), wrap=str(rng.choice(WRAPS)))
            options.update(texture=texture, sampler=sampler)
        scene.add(mesh, **options)
        result = mr.render(scene, _camera(rng), int(rng.integers(1, 24)), int(rng.integers(1, 24)),
                           spp=int(rng.choice([1, 4])), aa=str(rng.choice(["ssaa", "msaa"])),
                           threads=int(rng.integers(1, 3)), derivatives=str(rng.choice(["analytic", "quad"])))
        drawn += result.stats["samples_passed"] > 0
        c = result.color
        top = 1.0 if blend == "replace" else float(len(triangles))
        if not (np.isfinite(c).all() and c.min() >= 0.0 and c[..., :3].max() <= top + 1e-6
                and c[..., 3].max() <= 1.0 + 1e-6):
            finite = c[np.isfinite(c)]
            span = f"finite values in [{finite.min()}, {finite.max()}]" if finite.size else "no finite value"
            failures.append(f"case {case}: {int((~np.isfinite(c)).sum())} non-finite, {span}, "
                            f"{options.get('sampler')}, {options['interpolation']}, {blend}")
    assert drawn > 250, f"only {drawn} of 3000 cases drew a sample: the test would see little"
    assert not failures, "\n".join(failures[:10])
