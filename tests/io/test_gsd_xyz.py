"""GSD and extended XYZ: round trips, a real client (freud) reading what discsim writes, and foreign files."""

from __future__ import annotations

import numpy as np
import pytest

import discsim as ds

gsd_hoomd = pytest.importorskip("gsd.hoomd")


@pytest.fixture(scope="module")
def run():
    discs, box = ds.random_gas(500, 0.45, seed=7)
    groups = np.arange(500) % 2 * 3  # two groups, labels 0 and 3
    discs = ds.Discs(discs.positions, discs.velocities, discs.radii, 1.0 + (groups > 0), groups)
    return ds.EventDriven(discs, box).run(until=6.0)


def test_gsd_round_trip(tmp_path, run):
    times = [0.0, 2.0, 4.0, 6.0]
    exact = ds.frames(run, times)
    back = ds.read_gsd(ds.write_gsd(tmp_path / "run.gsd", run, times=times))
    assert back.times.tolist() == times
    scale = run.box.width
    assert np.abs(back.positions - exact.positions).max() < 1e-6 * scale  # float32, as HOOMD stores them
    assert np.abs(back.unwrapped - exact.unwrapped).max() < 1e-5 * scale
    assert np.allclose(back.velocities, exact.velocities, atol=1e-6)
    assert np.allclose(back.radii, 1.0) and back.groups.tolist() == run.discs.groups.tolist()
    assert np.allclose(back.masses, run.discs.masses) and back.box.periodic


def test_the_hoomd_layout(tmp_path, run):
    path = ds.write_gsd(tmp_path / "run.gsd", run)  # the state now: one frame
    with gsd_hoomd.open(str(path), "r") as handle:
        frame = handle[0]
        assert len(handle) == 1 and frame.configuration.dimensions == 2
        lx, _, lz = frame.configuration.box[:3]
        assert lz == 0 and lx == pytest.approx(run.box.width)
        pos = frame.particles.position
        assert (pos[:, 2] == 0).all() and (np.abs(pos[:, :2]) <= 0.5 * lx).all()  # HOOMD's centred box
        assert frame.particles.types == ["0", "3"] and set(frame.particles.typeid.tolist()) == {0, 1}
        assert np.allclose(frame.particles.diameter, 2.0)


def test_freud_reads_discsim_gsd_and_agrees_on_g_of_r(tmp_path, run):
    freud = pytest.importorskip("freud")
    times = [3.0, 4.0, 5.0, 6.0]
    path = ds.write_gsd(tmp_path / "run.gsd", run, times=times)
    rdf = freud.density.RDF(bins=120, r_max=6.0, normalization_mode="finite_size")
    with gsd_hoomd.open(str(path), "r") as handle:
        for frame in handle:
            box = freud.box.Box.from_box(frame.configuration.box, dimensions=frame.configuration.dimensions)
            assert box.is2D
            rdf.compute(system=(box, frame.particles.position), reset=False)
    ours = ds.rdf(ds.frames(run, times).positions, run.box, r_max=6.0, dr=0.05)
    assert np.allclose(rdf.bin_centers, ours.r, atol=1e-6)
    # freud counts each pair twice; float32 positions move the odd pair across a bin edge
    moved = np.abs(rdf.bin_counts / 2 - ours.counts)
    assert moved.max() <= 3 and moved.sum() <= 0.001 * ours.counts.sum()
    assert np.abs(rdf.rdf - ours.g).max() < 0.01
    assert np.abs(rdf.rdf - ours.g).mean() < 5e-4


def test_gsd_writer_observer(tmp_path):
    discs, box = ds.random_gas(100, 0.3, seed=1)
    sim = ds.EventDriven(discs, box, record=False)
    writer = ds.GSDWriter(tmp_path / "live.gsd", dt=0.5)
    sim.run(until=1.0, observers=[writer])
    sim.run(until=2.0, observers=[writer])  # the same writer continues its file
    back = ds.read_gsd(tmp_path / "live.gsd")
    assert back.times.tolist() == [0.0, 0.5, 1.0, 1.5, 2.0]
    exact = ds.frames(ds.EventDriven(discs, box).run(until=2.0), back.times)
    assert np.abs(back.positions - exact.positions).max() < 1e-5
    with pytest.raises(ds.InvalidArgumentError, match="already exists"):
        ds.EventDriven(discs, box).run(until=1.0, observers=[ds.GSDWriter(tmp_path / "live.gsd", dt=0.5)])


def test_walls_survive_a_gsd_round_trip(tmp_path):
    sim = ds.EventDriven(*ds.random_gas(50, 0.3, periodic=False, seed=1)).run(until=1.0)
    back = ds.read_gsd(ds.write_gsd(tmp_path / "walls.gsd", sim))
    assert not back.box.periodic and (back.unwrapped == back.positions).all()


def test_foreign_and_3d_gsd_files_are_refused(tmp_path):
    junk = tmp_path / "junk.gsd"
    junk.write_bytes(b"this is not a GSD file at all" * 10)
    with pytest.raises(ds.InvalidArgumentError, match="not a GSD file"):
        ds.read_gsd(junk)
    frame = gsd_hoomd.Frame()
    frame.configuration.box = [4.0, 4.0, 4.0, 0, 0, 0]
    frame.configuration.dimensions = 3
    frame.particles.N = 2
    frame.particles.position = np.array([[0, 0, 0.5], [1, 1, -1]], dtype=np.float32)
    with gsd_hoomd.open(str(tmp_path / "3d.gsd"), "w") as handle:
        handle.append(frame)
    with pytest.raises(ds.InvalidArgumentError, match="3D data"):
        ds.read_gsd(tmp_path / "3d.gsd")
    with pytest.raises(FileNotFoundError):
        ds.read_gsd(tmp_path / "missing.gsd")


def test_xyz_round_trip_is_exact(tmp_path, run):
    times = [0.0, 3.0, 6.0]
    exact = ds.frames(run, times)
    path = ds.write_xyz(tmp_path / "run.xyz", exact)
    back = ds.read_xyz(path)
    assert (back.positions == exact.positions).all() and (back.velocities == exact.velocities).all()
    assert back.times.tolist() == times and back.box == run.box
    assert (back.radii == exact.radii).all() and (back.groups == exact.groups).all()
    lines = path.read_text().splitlines()
    assert lines[0] == "500" and 'pbc="T T F"' in lines[1] and "Properties=species:S:1:pos:R:3:radius:R:1" in lines[1]
    assert lines[2].split()[0] in ("H", "He")


def test_foreign_and_3d_xyz_files_are_refused(tmp_path):
    bad = tmp_path / "bad.xyz"
    bad.write_text('2\nLattice="4 0 0 0 4 0 0 0 4" Properties=species:S:1:pos:R:3\nH 1 1 1\nH 2 2 0\n')
    with pytest.raises(ds.InvalidArgumentError, match="3D data|not a 2D rectangle"):
        ds.read_xyz(bad)
    bad.write_text('2\nLattice="4 0 0 0 4 0 0 0 0" Properties=species:S:1:pos:R:3\nH 1 1 1\nH 2 2 0\n')
    with pytest.raises(ds.InvalidArgumentError, match="3D data"):
        ds.read_xyz(bad)
    bad.write_text("hello\nworld\n")
    with pytest.raises(ds.InvalidArgumentError, match="count the discs"):
        ds.read_xyz(bad)
    bad.write_text('3\nLattice="4 0 0 0 4 0 0 0 0"\nH 1 1 0\n')
    with pytest.raises(ds.InvalidArgumentError, match="file ends"):
        ds.read_xyz(bad)
