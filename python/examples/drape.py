"""Drape the shipped T-shirt on a random body in a procedural pose and save the meshes.

    python3 python/examples/drape.py [OUT_DIR]

Writes OUT_DIR/draped.obj and OUT_DIR/body.obj (with trimesh when it is installed, else
by hand); OUT_DIR defaults to out/.
"""

import sys
from pathlib import Path

import garnet


def write_obj(path, vertices, faces):
    """A minimal OBJ: vertices in metres, 1-based triangles."""
    with open(path, "w") as f:
        for x, y, z in vertices:
            f.write(f"v {x} {y} {z}\n")
        for a, b, c in faces + 1:
            f.write(f"f {a} {b} {c}\n")


def save(path, vertices, faces):
    try:
        import trimesh
    except ImportError:
        write_obj(path, vertices, faces)
    else:
        trimesh.Trimesh(vertices, faces, process=False).export(path)
    print(f"wrote {path}")


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else "out")
    out.mkdir(parents=True, exist_ok=True)
    body = garnet.Body.random(1, pose=garnet.Pose.procedural(1))
    draper = garnet.Draper(garnet.shipped_models_dir() / "tshirt-local.garnet")
    result = draper.drape(body)
    t = result.timings
    print(
        f"{result.kind}: {len(result.vertices)} vertices on a {body.height * 100:.1f} cm body, "
        f"{body.pose.description}: network {t['network_ms']:.1f} ms"
    )
    save(out / "draped.obj", result.vertices, result.faces)
    save(out / "body.obj", result.body_vertices, result.body_faces)


if __name__ == "__main__":
    main()
