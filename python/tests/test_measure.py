"""The measurement toolkit: metrics against hand values, references and their shards,
compare's rows."""

import csv

import numpy as np
import pytest

import restir_pt
from conftest import CORNELL


def test_metrics_match_their_formulas():
    rng = np.random.default_rng(4)
    ref = rng.random((6, 5, 3), dtype=np.float32)
    img = (ref + rng.normal(0, 0.1, ref.shape)).astype(np.float32)
    x, r = img.astype(np.float64), ref.astype(np.float64)
    assert restir_pt.rel_mse(img, ref) == pytest.approx(np.mean((x - r) ** 2 / (r * r + 0.01)), rel=1e-5)
    assert restir_pt.mape(img, ref) == pytest.approx(np.mean(np.abs(x - r) / (r + 0.01)), rel=1e-5)
    assert restir_pt.mse(img, ref) == pytest.approx(np.mean((x - r) ** 2), rel=1e-5)
    assert restir_pt.rel_mse_trimmed(img, ref, 0.0) == pytest.approx(restir_pt.rel_mse(img, ref), rel=1e-9)
    assert restir_pt.mape(ref, ref) == 0.0 and restir_pt.rel_mse(ref, ref) == 0.0
    # float64 input is converted.
    assert restir_pt.rel_mse(x, r) == pytest.approx(restir_pt.rel_mse(img, ref), rel=1e-6)


def test_flip_is_zero_for_equal_images_and_grows_with_noise():
    rng = np.random.default_rng(5)
    ref = rng.random((32, 32, 3), dtype=np.float32)
    assert restir_pt.flip(ref, ref) == 0.0
    little = restir_pt.flip(ref + rng.normal(0, 0.02, ref.shape).astype(np.float32), ref, exposure=0.0)
    much, heat = restir_pt.flip(ref + rng.normal(0, 0.3, ref.shape).astype(np.float32), ref, exposure=0.0, error_map=True)
    assert 0.0 < little < much <= 1.0
    assert heat.shape == (32, 32) and heat.dtype == np.float32
    assert heat.mean() == pytest.approx(much, rel=1e-5)


def test_hdr_flip_matches_nvidias_flip_evaluator():
    """HDR-FLIP against NVIDIA's own implementation (PyPI flip-evaluator, float inputs): ours
    quantises each tone-mapped exposure to 8-bit sRGB for nv-flip, so means agree within 5%
    and the error maps correlate above 0.95 on images with a radiance range of 2^10."""
    flip_evaluator = pytest.importorskip("flip_evaluator")
    rng = np.random.default_rng(11)
    y, x = np.mgrid[0:64, 0:80].astype(np.float32)
    ref = np.stack([x / 80, y / 64, np.full_like(x, 0.3)], axis=-1) * np.exp2(10 * x / 80)[..., None]
    ref = ref.astype(np.float32)
    for noise in (0.05, 0.3):
        test = (ref * np.exp(rng.normal(0, noise, ref.shape))).astype(np.float32)
        ours, ours_map = restir_pt.hdr_flip(test, ref, error_map=True)
        theirs_map, theirs, _ = flip_evaluator.evaluate(ref, test, "HDR", applyMagma=False)
        assert ours == pytest.approx(theirs, rel=0.05), noise
        assert np.corrcoef(ours_map.ravel(), np.asarray(theirs_map).ravel())[0, 1] > 0.95
    assert restir_pt.hdr_flip(ref, ref) == 0.0


def test_reference_shards_merge_into_the_one_process_reference(tmp_path, cornell):
    whole, whole_var = restir_pt.reference(cornell, spp=12, width=16, height=16, seed=4, out=tmp_path / "ref.exr")
    assert (tmp_path / "ref.json").exists() and (tmp_path / "ref.variance.exr").exists()
    assert np.array_equal(restir_pt.read_exr(tmp_path / "ref.exr"), whole)
    paths = []
    for i in range(3):
        paths.append(tmp_path / f"ref.{i}.exr")
        restir_pt.reference(cornell, spp=12, width=16, height=16, seed=4, shard=f"{i}/3", out=paths[-1])
    with pytest.warns(UserWarning, match=r"shards \[2\] of 3 are missing"):
        restir_pt.merge_shards(paths[:2])
    mean, var = restir_pt.merge_shards(paths, out=tmp_path / "merged.exr")
    # Within f32 rounding of the sums (mean 1e-5, variance 1e-3 relative), as the Rust suite.
    np.testing.assert_allclose(mean, whole, rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(var, whole_var, rtol=1e-3, atol=1e-9)
    assert np.array_equal(restir_pt.read_exr(tmp_path / "merged.exr"), mean)
    with pytest.raises(restir_pt.SettingsError, match="expected I/N"):
        restir_pt.reference(cornell, spp=12, shard="3/3", out=tmp_path / "x.exr")


def test_compare_returns_the_rows_of_results_csv(tmp_path, cornell):
    restir_pt.reference(cornell, spp=64, width=16, height=16, camera=1, out=tmp_path / "ref1.exr")
    rows = restir_pt.compare(
        CORNELL, tmp_path / "ref1.exr", methods=["pt", "restir@s0"], budgets_ms=[1000.0],
        frames=2, camera_path=True, out_dir=tmp_path / "cmp",
    )
    assert [r["method"] for r in rows] == ["pt", "restir:hybrid/gbh@s0"]
    with open(tmp_path / "cmp" / "results.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == len(rows)
    for row, line in zip(rows, table):
        assert row["knob"] == line["knob"] and row["budget_ms"] == 1000.0
        assert row["rel_mse"] == pytest.approx(float(line["rel_mse"]), rel=1e-3)
        assert row["nonfinite_pixels"] == 0 and 0.5 < row["energy_ratio"] < 1.5
        assert row["mape"] == pytest.approx(float(line["mape"]), rel=1e-3) and row["mape"] > 0
        assert 0 < row["hdr_flip"] < 1 and row["pt_samples_per_frame"] > 0
    assert rows[0]["failed_shift_rate"] is None and rows[1]["failed_shift_rate"] is not None
