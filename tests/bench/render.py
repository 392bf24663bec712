"""Side-by-side pictures of reconstructions, drawn the same way for every pipeline.

A small point-splatting renderer in numpy (no GPU, no display): each mesh is sampled
area-uniformly, the samples are projected orthographically, and per pixel the nearest
sample wins. A sample keeps the normal of its triangle *as wound*, so a surface seen from
its back — inside-out — is painted red, and a missing part shows the white background.

A mesh path that is missing, unreadable or holds no triangle raises (Open3D's reader
returns an empty mesh for a missing file, which once made every panel silently blank), and
so does a panel whose mesh leaves every pixel background. A pipeline that produced no
output is a panel given None: it is drawn grey and labelled so.
"""
from pathlib import Path

import numpy as np

FRONT = np.array([0.72, 0.80, 0.92])  # outward side facing the camera
BACK = np.array([0.93, 0.28, 0.22])   # inward side facing the camera: inside-out
BACKGROUND = 1.0


def read_mesh(path):
    """(vertices n×3, triangles m×3) of a .ply / .off / .obj, through Open3D's reader.
    Raises FileNotFoundError for a missing file and ValueError for one without triangles."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"mesh to render not found: {path}")
    import open3d as o3d

    mesh = o3d.io.read_triangle_mesh(str(path))
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    triangles = np.asarray(mesh.triangles, dtype=np.int64)
    if len(vertices) == 0 or len(triangles) == 0:
        raise ValueError(f"mesh to render is empty or unreadable: {path} "
                         f"({len(vertices)} vertices, {len(triangles)} triangles)")
    return vertices, triangles


def camera(azimuth_deg, elevation_deg):
    """Rotation world → camera (x right, y up, z toward the viewer), world +y up."""
    a, e = np.radians(azimuth_deg), np.radians(elevation_deg)
    toward_viewer = np.array([np.sin(a) * np.cos(e), np.sin(e), np.cos(a) * np.cos(e)])
    right = np.cross([0.0, 1.0, 0.0], toward_viewer)
    right /= np.linalg.norm(right)
    up = np.cross(toward_viewer, right)
    return np.stack([right, up, toward_viewer])


def render(vertices, triangles, rotation, center, half_extent, size=420, seed=0):
    """An RGB image (size×size×3, floats in [0, 1]) of the mesh; center and half_extent (in
    world units) frame the view, so panels that share them share the camera."""
    image = np.full((size, size, 3), BACKGROUND)
    if len(triangles) == 0:
        return image
    corners = vertices[triangles]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    double_area = np.linalg.norm(cross, axis=1)
    keep = double_area > 0
    corners, cross, double_area = corners[keep], cross[keep], double_area[keep]
    if len(corners) == 0:
        return image
    normals = cross / double_area[:, None]

    # About eight samples per covered pixel, so that the splats close up.
    scale = size / (2 * half_extent)
    count = int(min(6e6, max(2e5, 8 * 0.5 * double_area.sum() * scale**2)))
    rng = np.random.default_rng(seed)
    tri = rng.choice(len(corners), size=count, p=double_area / double_area.sum())
    r1, r2 = np.sqrt(rng.random(count)), rng.random(count)
    points = ((1 - r1)[:, None] * corners[tri, 0] + (r1 * (1 - r2))[:, None] * corners[tri, 1]
              + (r1 * r2)[:, None] * corners[tri, 2])

    cam = (points - center) @ rotation.T
    px = np.floor(cam[:, 0] * scale + size / 2).astype(np.int64)
    py = np.floor(size / 2 - cam[:, 1] * scale).astype(np.int64)
    inside = (px >= 0) & (px < size) & (py >= 0) & (py < size)
    px, py, depth, tri = px[inside], py[inside], cam[inside, 2], tri[inside]
    if len(px) == 0:
        return image
    pixel = py * size + px
    order = np.lexsort((depth, pixel))  # by pixel, then nearest (largest z) last
    last = np.r_[np.nonzero(np.diff(pixel[order]))[0], len(order) - 1]
    winners = order[last]

    n = normals[tri[winners]] @ rotation.T       # in camera coordinates
    # Grazing triangles at a silhouette may win a pixel from either side; only a clearly
    # back-facing surface is inside-out.
    facing = n[:, 2] > -0.15
    n_front = np.where(facing[:, None], n, -n)    # light whichever side is seen
    light = np.array([0.35, 0.55, 1.0]) / np.linalg.norm([0.35, 0.55, 1.0])
    intensity = 0.25 + 0.75 * np.clip(n_front @ light, 0, 1)
    color = np.where(facing[:, None], FRONT, BACK) * intensity[:, None]
    flat = image.reshape(-1, 3)
    flat[pixel[winners]] = color
    return image


def side_by_side(panels, path, title, azimuth=35, elevation=20, frame=None, size=420):
    """panels: list of (label, mesh) where mesh is a path, a (vertices, triangles) pair, or
    None for a pipeline that produced no output. frame: (center, half_extent), else the
    first mesh's bounding box. Writes one PNG and returns the panel images (None for the
    panels without output). Raises on a missing or empty mesh and on a blank panel."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    meshes = [(label, read_mesh(mesh) if isinstance(mesh, (str, Path)) else mesh) for label, mesh in panels]
    if frame is None:
        first = next((m for _, m in meshes if m is not None), None)
        if first is None:
            raise ValueError(f"{title}: no panel has a mesh to render")
        lo, hi = first[0].min(axis=0), first[0].max(axis=0)
        frame = ((lo + hi) / 2, 0.55 * np.linalg.norm(hi - lo))
    center, half_extent = frame
    rotation = camera(azimuth, elevation)

    images = []
    for label, mesh in meshes:
        image = None
        if mesh is not None:
            image = render(mesh[0], mesh[1], rotation, np.asarray(center), half_extent, size)
            if not (image != BACKGROUND).any():
                raise ValueError(f"{title}: the panel '{label.splitlines()[0]}' is blank "
                                 "(its mesh lies outside the frame or has no area)")
        images.append(image)

    fig, axes = plt.subplots(1, len(meshes), figsize=(3.2 * len(meshes), 3.6), squeeze=False)
    for ax, (label, _), image in zip(axes[0], meshes, images):
        if image is None:
            ax.imshow(np.full((size, size, 3), 0.9))
            label = f"{label}\n(no output)"
        else:
            ax.imshow(image)
        ax.set_title(label, fontsize=9)
        ax.set_axis_off()
    fig.suptitle(f"{title}   (red = surface seen from inside: inside-out)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return images
