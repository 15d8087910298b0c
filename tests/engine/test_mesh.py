"""Graded meshes (sweep.engine.mesh), the stop rule and the error estimate of a result."""
import numpy as np
import pytest

from sweep.kernels.solve import stop_reached
from sweep import Numerics, Scene
from sweep.engine.bem import simulate  # the BEM on the graded mesh (not the model dispatch)
from sweep.engine.mesh import crack_band, graded_mesh, graded_mesh_with_nodes, uniform_mesh


def test_graded_mesh_is_fine_in_the_band_and_grows_geometrically_outside():
    spacing, grading = 0.01, 1.1
    mesh = graded_mesh(6.0, crack_band(3.0, 0.16), spacing, grading)
    r, d = np.asarray(mesh.r), np.diff(mesh.r)
    assert r[0] == 0.0 and r[-1] == pytest.approx(6.0, abs=spacing)
    assert np.all(d > 0)
    lo, hi = mesh.band
    assert lo <= 0.3 * 3.0 - 0.6 + spacing and hi >= 1.05 * 3.0 + 0.64 - spacing
    inside = (r[:-1] >= lo - 1e-12) & (r[1:] <= hi + 1e-12)
    np.testing.assert_allclose(d[inside], spacing, rtol=1e-9)
    assert d.max() > 10 * spacing                              # coarse far from the band
    ratio = d[1:] / d[:-1]
    assert np.all((ratio < 2.01) & (ratio > 1 / 2.01))         # no abrupt jumps
    np.testing.assert_allclose(r / spacing, mesh.lattice, atol=1e-9)
    assert mesh.nodes < 0.7 * uniform_mesh(601, 6.0).nodes


def test_graded_mesh_with_a_node_count():
    for n in (60, 137, 400):
        mesh = graded_mesh_with_nodes(n, 5.0, (1.0, 3.5), 1.1)
        assert n - 3 <= mesh.nodes <= n


def _lattice_dip_records():
    # load falling towards the pull-off, with a lattice dip: the tip snaps by one node
    # (0.02), the load recovers by 8 % for a few steps, then falls again
    a = np.concatenate([np.linspace(2.0, 1.5, 20), [1.48] * 7, np.linspace(1.47, 1.0, 20)])
    P = np.concatenate([np.linspace(-1.0, -2.0, 20), np.linspace(-1.84, -1.80, 7),
                        np.linspace(-2.1, -2.5, 10), np.linspace(-2.45, -1.5, 10)])
    return P, a


def test_stop_rule_does_not_end_on_a_lattice_dip():
    P, a = _lattice_dip_records()
    spacing = 0.02
    stops = [n for n in range(2, P.size + 1)
             if stop_reached(P, a, n, int(np.argmin(P[:n])), 0, 3 * spacing)]
    assert stops and stops[0] > 37              # past the true minimum (index 36)
    # without the tip-travel condition the dip would have ended the run
    early = [n for n in range(2, P.size + 1)
             if stop_reached(P, a, n, int(np.argmin(P[:n])), 0, 0.0)]
    assert early[0] < 30


def test_coarse_numerics_never_report_a_wrong_pull_off_as_ok():
    # the new-user scene: truth about 2.04 (300+ nodes)
    scene = Scene(n=0.4, k=0.1, mu=3.24, a0=2, rate=1)
    coarse = simulate(scene, Numerics.preset("fast", nodes=60))
    assert not coarse.ok and coarse.reason.startswith("unresolved")
    assert coarse.error_estimate > 0.03
    fast = simulate(scene, Numerics.preset("fast"))
    ref = simulate(scene, Numerics.preset("balanced"))
    assert fast.ok and ref.ok
    # the indicator (change against half the resolution) bounds the actual error
    assert abs(fast.pull_off / ref.pull_off - 1) < fast.error_estimate < 0.03
    assert ref.pull_off == pytest.approx(2.04, rel=0.01)


def test_graded_and_uniform_meshes_agree_at_the_same_spacing():
    scene = Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=100.0)
    g = simulate(scene, Numerics.preset("balanced", pull_off_rtol=0.0))
    nodes = int(round(g.domain_used / g.spacing)) + 1
    u = simulate(scene, Numerics.preset("balanced", mesh="uniform", nodes=nodes, pull_off_rtol=0.0))
    assert g.ok and u.ok and g.nodes_used < 0.7 * u.nodes_used
    assert g.pull_off == pytest.approx(u.pull_off, rel=1e-4)


def test_unit_matrix_grows_by_blocks_to_the_fully_assembled_one():
    from sweep.kernels.influence import assemble_unit, grow_unit
    full = assemble_unit(90)
    grown = grow_unit(assemble_unit(37), 90)
    np.testing.assert_array_equal(grown, full)        # the same quadrature, entry by entry
    np.testing.assert_array_equal(grow_unit(np.zeros((0, 0)), 90), full)


def test_unit_matrix_disk_cache_is_written_reused_and_survives_a_bad_file(tmp_path,
                                                                         monkeypatch):
    from sweep.kernels.influence import assemble_unit
    from sweep.engine import diskcache
    from sweep.engine import mesh
    monkeypatch.setenv(diskcache.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(mesh, "UNIT_BLOCK", 32)
    monkeypatch.setattr(mesh, "_UNIT", [np.zeros((0, 0))])
    a = np.array(mesh.unit_influence(40))
    np.testing.assert_array_equal(a, assemble_unit(64)[:40, :40])
    files = sorted(tmp_path.glob("unit_influence_*_64.npy"))
    assert len(files) == 1
    # a new process (empty memory) reads it back instead of assembling: poison the
    # assembly to prove it is not called
    monkeypatch.setattr(mesh, "_UNIT", [np.zeros((0, 0))])
    monkeypatch.setattr(mesh, "grow_unit", lambda *a: (_ for _ in ()).throw(AssertionError))
    np.testing.assert_array_equal(mesh.unit_influence(50), assemble_unit(64)[:50, :50])
    # growing past the cached size starts from the cached block, replaces the file
    monkeypatch.undo()
    monkeypatch.setenv(diskcache.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(mesh, "UNIT_BLOCK", 32)
    monkeypatch.setattr(mesh, "_UNIT", [np.zeros((0, 0))])
    np.testing.assert_array_equal(mesh.unit_influence(70), assemble_unit(96)[:70, :70])
    assert [p.name.rsplit("_", 1)[1] for p in tmp_path.glob("unit_influence_*.npy")] == \
        ["96.npy"]
    # a damaged file is ignored (assembled again, and rewritten)
    bad = next(tmp_path.glob("unit_influence_*.npy"))
    bad.write_bytes(b"not a matrix")
    monkeypatch.setattr(mesh, "_UNIT", [np.zeros((0, 0))])
    np.testing.assert_array_equal(mesh.unit_influence(20), assemble_unit(32)[:20, :20])
    # switched off: nothing written
    off = tmp_path / "off"
    monkeypatch.setenv(diskcache.CACHE_ENV, "off")
    monkeypatch.setattr(mesh, "_UNIT", [np.zeros((0, 0))])
    mesh.unit_influence(20)
    assert diskcache.cache_dir() is None and not off.exists()
