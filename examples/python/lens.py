"""snell from Python: a glass sphere squashed frame by frame, with vertices from numpy (docs/python.md)."""
import numpy as np
import snell

def sphere(rings=24, segments=32):
    theta, phi = np.meshgrid(np.linspace(0, np.pi, rings + 1), np.linspace(0, 2 * np.pi, segments + 1), indexing="ij")
    n = np.stack([np.sin(theta) * np.cos(phi), np.cos(theta), np.sin(theta) * np.sin(phi)], -1).reshape(-1, 3)
    a = (np.arange(rings)[:, None] * (segments + 1) + np.arange(segments)[None, :]).reshape(-1)
    b = a + segments + 1
    faces = np.concatenate([np.stack([a, a + 1, b], 1), np.stack([a + 1, b + 1, b], 1)])
    return (0.5 * n).astype(np.float32), n.astype(np.float32), faces.astype(np.uint32)

wall = (np.float32([[-2, -2, -1], [2, -2, -1], [2, 2, -1], [-2, 2, -1]]), np.float32([[0, 0, 1]] * 4),
        np.uint32([[0, 1, 2], [0, 2, 3]]), np.float32([[0, 8], [8, 8], [8, 0], [0, 0]]))
checker = np.kron((np.indices((2, 2)).sum(0) % 2), np.ones((4, 4))).astype(np.uint8)[..., None] * [200, 150, 40, 0]
texture = snell.Texture((checker + [40, 60, 150, 255]).astype(np.uint8))
positions, normals, indices = sphere()

with snell.Device() as device:
    scene = snell.Scene.from_arrays(
        [snell.Mesh(*wall, material=0), snell.Mesh(positions, normals, indices, material=1)],
        materials=[snell.Material(base_color_texture=0), snell.Material(transmission=1.0, ior=1.45)],
        textures=[texture])
    renderer = snell.Renderer(device, scene)
    view = snell.View(320, 240, eye=(0, 0, 3), target=(0, 0, 0))
    for frame in range(4):
        squash = np.float32([1 + 0.1 * frame, 1 - 0.1 * frame, 1 + 0.1 * frame])
        np.copyto(renderer.positions(1), positions * squash)  # straight into snell's mapped memory
        np.copyto(renderer.normals(1), normals / squash / np.linalg.norm(normals / squash, axis=1, keepdims=True))
        renderer.mark_dirty(1)                                # the next frame refits this mesh alone
        rgba = renderer.render(view)                          # (240, 320, 4) float32, scene-linear
        srgb = np.where(rgba <= 0.0031308, 12.92 * rgba, 1.055 * np.clip(rgba, 0, 1) ** (1 / 2.4) - 0.055)
        with open(f"lens_{frame}.ppm", "wb") as out:
            out.write(b"P6 320 240 255\n" + (np.clip(srgb[..., :3], 0, 1) * 255).round().astype(np.uint8).tobytes())
        print(frame, renderer.last_frame()["gpu_ms"], "ms on the GPU")
