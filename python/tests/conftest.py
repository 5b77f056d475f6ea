"""Shared fixtures: the repository, the `garnet` binary, mesh and safetensors readers."""

import json
import os
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
TSHIRT = REPO / "models" / "tshirt-local.garnet"


@pytest.fixture(scope="module")
def garnet_bin() -> Path:
    """The release binary (`cargo build --release`), or $GARNET_BIN."""
    path = Path(os.environ.get("GARNET_BIN", REPO / "target" / "release" / "garnet"))
    if not path.is_file():
        pytest.fail(f"{path} is missing: build it with `cargo build --release`")
    return path


def run(binary: Path, *args: str) -> subprocess.CompletedProcess:
    """Runs the binary from the repository root; fails the test, showing stderr, on error."""
    done = subprocess.run(
        [str(binary), *args], cwd=REPO, capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        pytest.fail(f"garnet {' '.join(args)} failed:\n{done.stderr}")
    return done


def read_obj(path: Path):
    """Vertices float64 [N,3] and faces int64 [F,3] (0-based) of an OBJ file."""
    vertices, faces = [], []
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts[0] == "f":
            faces.append([int(p.split("/")[0]) - 1 for p in parts[1:4]])
    return np.array(vertices, dtype=np.float64), np.array(faces, dtype=np.int64)


def read_safetensors(path: Path):
    """The tensors of a safetensors file, read by hand: {name: numpy array}, metadata."""
    data = Path(path).read_bytes()
    (n,) = struct.unpack("<Q", data[:8])
    header = json.loads(data[8 : 8 + n])
    meta = header.pop("__metadata__", {})
    dtypes = {"F32": "<f4", "F64": "<f8", "I64": "<i8", "I32": "<i4", "U32": "<u4", "U8": "u1"}
    out = {}
    for name, t in header.items():
        start, end = t["data_offsets"]
        buf = data[8 + n + start : 8 + n + end]
        out[name] = np.frombuffer(buf, dtype=dtypes[t["dtype"]]).reshape(t["shape"])
    return out, meta
