"""Extended XYZ files written by other tools: defaults, species as groups, columns of the wrong type."""

from __future__ import annotations

import pytest

import discsim as ds

LATTICE = 'Lattice="4 0 0 0 3 0 0 0 0"'


def test_a_file_with_species_and_positions_only_takes_the_defaults(tmp_path):
    path = tmp_path / "ase.xyz"
    frame = f'3\n{LATTICE} Properties=species:S:1:pos:R:3 pbc="F F F" Time={{t}}\nHe 1 1 0\nH 2 2 0\nHe 3 1 0\n'
    path.write_text(frame.format(t=0.0) + frame.format(t=0.5))
    back = ds.read_xyz(path)
    assert back.times.tolist() == [0.0, 0.5] and back.box == ds.Box(4.0, 3.0, periodic=False)
    assert back.positions.shape == (2, 3, 2) and back.positions[1, 2].tolist() == [3.0, 1.0]
    assert back.groups.tolist() == [1, 0, 1]  # species numbered in sorted order: H 0, He 1
    assert back.radii.tolist() == [0.5] * 3 and back.masses.tolist() == [1.0] * 3
    assert not back.velocities.any() and (back.unwrapped == back.positions).all()


@pytest.mark.parametrize(
    ("properties", "row"),
    [("species:S:1:pos:S:3", "H 1 1 0"), ("species:S:1:pos:R:3:group:S:1", "H 1 1 0 a")],
)
def test_a_number_column_declared_text_is_refused(tmp_path, properties, row):
    path = tmp_path / "text.xyz"
    path.write_text(f"1\n{LATTICE} Properties={properties}\n{row}\n")
    with pytest.raises(ds.InvalidArgumentError, match=r"column (pos|group) is declared text \(S\)"):
        ds.read_xyz(path)


def test_frames_with_other_discs_or_no_frame_are_refused(tmp_path):
    path = tmp_path / "two.xyz"
    path.write_text(f"1\n{LATTICE} Properties=species:S:1:pos:R:3\nH 1 1 0\n2\n{LATTICE}\nH 1 1 0\nH 2 2 0\n")
    with pytest.raises(ds.InvalidArgumentError, match="differs from frame 0"):
        ds.read_xyz(path)
    path.write_text("\n\n")
    with pytest.raises(ds.InvalidArgumentError, match="holds no frame"):
        ds.read_xyz(path)
