"""garnet.Dataset against the shard files `garnet dataset generate` writes."""

import shutil

import numpy as np
import pytest

import garnet
from conftest import read_safetensors, run

# A tiny dataset (procedural poses only, 3 bodies, an 8 cm T-shirt, a few simulator steps),
# as the command line's own tests make it.
SPEC = """
name = "python-tests"
seed = 4
shard_size = 2
[bodies]
count = 3
[[garments]]
kind = "tshirt"
edge = 0.08
poses_per_body = 2
[[poses.procedural]]
kind = "walk"
count = 4
[splits.bodies]
train = 1
val = 1
test = 1
[simulator]
morph_steps = 2
pose_steps = 3
max_settle_steps = 5
iterations = 2
max_penetration = 0.5
skinning = "lbs"
"""


@pytest.fixture(scope="module")
def data(garnet_bin, tmp_path_factory):
    """The dataset folder. The spec format may ask for a `format` line: given when it does."""
    tmp = tmp_path_factory.mktemp("dataset")
    spec = tmp / "spec.toml"
    out = tmp / "data"
    args = ["dataset", "generate", str(spec), "--out", str(out), "--jobs", "2"]
    spec.write_text(SPEC)
    import subprocess

    from conftest import REPO

    done = subprocess.run([str(garnet_bin), *args], cwd=REPO, capture_output=True, text=True)
    if done.returncode != 0 and "format" in done.stderr:
        shutil.rmtree(out, ignore_errors=True)
        spec.write_text("format = 2\n" + SPEC)
        run(garnet_bin, *args)
    elif done.returncode != 0:
        pytest.fail(f"garnet dataset generate failed:\n{done.stderr}")
    return out


def shard_tensors(data):
    tensors = {}
    for shard in sorted((data / "shards").glob("*.safetensors")):
        t, meta = read_safetensors(shard)
        assert "garnet_dataset_shard" in meta
        tensors.update(t)
    return tensors


def test_samples_equal_the_shards_tensors(data):
    ds = garnet.Dataset(data)
    tensors = shard_tensors(data)
    stored = sorted({int(name.split(".")[0]) for name in tensors})
    assert ds.indices == stored and len(ds) == len(stored) > 0
    body_faces = ds.body_faces
    for i in range(len(ds)):
        s = ds[i]
        k = f"{s['index']:010}"
        for key, name in [
            ("body", "body"), ("warped", "warped"), ("draped", "draped"),
            ("rotations", "pose.rotations"), ("root_translation", "pose.root"),
            ("phenotype", "phenotype"),
        ]:
            assert s[key].dtype == np.float32
            np.testing.assert_array_equal(s[key], tensors[f"{k}.{name}"], err_msg=key)
        assert s["garment"] == "tshirt" and s["split"] in ("train", "val", "test")
        assert s["faces"].dtype == np.uint32 and s["faces"].max() < len(s["draped"])
        assert body_faces.max() < len(s["body"])
        assert isinstance(s["stats"], dict) and isinstance(s["pose"], str)
    assert ds[-1]["index"] == ds.indices[-1]
    with pytest.raises(IndexError):
        ds[len(ds)]


def test_safetensors_package_reads_the_same(data):
    import safetensors.numpy as numpy_st
    ds = garnet.Dataset(data)
    s = ds[0]
    for shard in (data / "shards").glob("*.safetensors"):
        t = numpy_st.load_file(str(shard))
        name = f"{s['index']:010}.draped"
        if name in t:
            np.testing.assert_array_equal(s["draped"], t[name])
            return
    pytest.fail("sample 0 is in no shard")


def test_splits_and_garments(data):
    for split in ("train", "val", "test"):
        ds = garnet.Dataset(data, split=split)
        assert len(ds) > 0 and all(s["split"] == split for s in ds)
    assert sorted(garnet.Dataset(data).splits) == ["test", "train", "val"]
    with pytest.raises(ValueError, match="split"):
        garnet.Dataset(data, split="holdout")
    with pytest.raises(FileNotFoundError):
        garnet.Dataset(data / "none")


def test_metrics_on_a_sample(data):
    s = garnet.Dataset(data)[0]
    assert garnet.metrics.e_dist(s["draped"], s["draped"]) == 0.0
    assert garnet.metrics.e_dist(s["draped"], s["warped"]) > 0.0
    assert garnet.metrics.e_norm(s["draped"], s["warped"], s["faces"]) > 0.0


def test_a_damaged_shard_raises(data, tmp_path):
    copy = tmp_path / "data"
    shutil.copytree(data, copy)
    shard = sorted((copy / "shards").glob("*.safetensors"))[0]
    raw = bytearray(shard.read_bytes())
    raw[-1] ^= 0xFF
    shard.write_bytes(bytes(raw))
    ds = garnet.Dataset(copy)
    with pytest.raises(garnet.GarnetError, match="checksum mismatch"):
        ds[0]


def test_the_dataset_is_a_map_style_sequence(data):
    """What PyTorch's DataLoader asks of a map-style dataset: len, int indices, IndexError
    past the end; arrays that wrap the shard's buffer without a copy (torch.from_numpy
    shares them)."""
    ds = garnet.Dataset(data, split="train")
    assert len(ds) == len(list(iter(ds)))
    s = ds[0]
    assert s["draped"].dtype == np.float32 and s["draped"].flags["C_CONTIGUOUS"]
    assert ds[int(np.int64(0))]["index"] == s["index"]
    with pytest.raises(IndexError):
        ds[len(ds)]
