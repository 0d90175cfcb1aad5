"""The cache of generated model files is used only when it is this user's alone, and what
is read back from it is what was written.

Each test runs in its own temporary folder (tempfile.tempdir patched), so the real
`$TMPDIR/pinmech-<uid>` is never touched. The models' numbers are checked against the
four-bar's closed form (scripts/closed_form.py): a tampered model moves its points by
millimetres, far above the 1e-10 m allowed (loops close to ~1e-13 of the 0.1 m mechanism).
"""

from __future__ import annotations

import math
import os
import stat
import tempfile
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import closed_form as cf
from pinmech import LoopSolver, user_cache
from pinmech.model.linkage_model import load_linkage
from pinmech.model.mjcf import load_mjcf
from tests.tolerance import rounding

ROOT = Path(__file__).resolve().parents[1]
LINKAGE = ROOT / "models" / "linkages" / "four_bar.toml"
MJCF = ROOT / "models" / "mjcf" / "four_bar.xml"


@pytest.fixture
def tmpdir_of_test(tmp_path, monkeypatch) -> Path:
    """A temporary folder of the test's own in place of the shared one."""
    shared = tmp_path / "shared-tmp"
    shared.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(shared))
    monkeypatch.setattr(user_cache, "_fallback", None)
    return shared


def _shared_folder(tmp: Path) -> Path:
    return tmp / f"pinmech-{os.getuid()}"


def test_the_cache_folder_is_made_private_and_its_file_holds_the_text(tmpdir_of_test):
    path = user_cache.cached_text("linkage", ".urdf", "<robot name='x'/>\n")
    assert path.parent == _shared_folder(tmpdir_of_test)
    assert stat.S_IMODE(os.lstat(path.parent).st_mode) == 0o700
    assert path.read_text() == "<robot name='x'/>\n"
    before = os.stat(path).st_ino
    assert user_cache.cached_text("linkage", ".urdf", "<robot name='x'/>\n") == path
    assert os.stat(path).st_ino == before  # verified, not rewritten
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temporary file left


def _plant_other_owners_folder(folder: Path, monkeypatch) -> None:
    """A folder another user made first: owned by another uid (as root, truly; else this
    process is told it is someone else)."""
    folder.mkdir(mode=0o700)
    if os.geteuid() == 0:
        os.chown(folder, 65534, -1)
    else:
        monkeypatch.setattr(user_cache, "_uid", lambda: os.getuid() + 1)


@pytest.mark.parametrize("plant", ["other owner", "open to others", "symbolic link"])
def test_a_shared_folder_not_ours_alone_is_not_used(tmpdir_of_test, tmp_path, monkeypatch, plant):
    folder = _shared_folder(tmpdir_of_test)
    if plant == "other owner":
        _plant_other_owners_folder(folder, monkeypatch)
    elif plant == "open to others":
        folder.mkdir()
        os.chmod(folder, 0o777)
    else:
        target = tmp_path / "elsewhere"
        target.mkdir(mode=0o700)
        folder.symlink_to(target)
    path = user_cache.cached_text("linkage", ".urdf", "<robot name='x'/>\n")
    assert path.parent != folder and folder not in path.parents and (tmp_path / "elsewhere") not in path.parents
    for mech in (load_linkage(LINKAGE), load_mjcf(MJCF)):  # what the loaders use
        assert Path(mech.urdf_path).parent == path.parent
    info = os.lstat(path.parent)
    assert stat.S_ISDIR(info.st_mode) and stat.S_IMODE(info.st_mode) == 0o700
    assert path.read_text() == "<robot name='x'/>\n"


def _rocker_angle(mech, theta2: float) -> float:
    """The rocker's angle [rad] in the world with the crank turned by theta2 from the reference."""
    solver = LoopSolver(mech, [next(iter(mech.joints))])
    q = mech.reference if mech.reference is not None else mech.neutral()
    start = mech.coordinate(q, next(iter(mech.joints)))
    for value in np.linspace(start, start + theta2, 4)[1:]:
        q = solver.solve([value], guess=q).q
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    x = data.oMf[mech.links["rocker"]].rotation[:, 0]
    return math.atan2(x[1], x[0])


def test_a_tampered_linkage_urdf_is_not_loaded(tmpdir_of_test):
    """Another crank length written into the cached URDF: the next load rebuilds it, and the
    drawn four-bar (crank 40, coupler 120, rocker 80, ground 100 mm) moves as Norton's."""
    first = load_linkage(LINKAGE)
    cached = Path(first.urdf_path)
    cached.write_text(cached.read_text().replace('name="A" type="continuous"><parent link="crank"/>'
                                                 '<child link="coupler"/><origin xyz="0.04 0 0"/>',
                                                 'name="A" type="continuous"><parent link="crank"/>'
                                                 '<child link="coupler"/><origin xyz="0.05 0 0"/>'))
    assert "0.05 0 0" in cached.read_text()  # the tampering took
    mech = load_linkage(LINKAGE)
    assert "0.05 0 0" not in Path(mech.urdf_path).read_text()
    ref = cf.four_bar(0.3, 1.0, 0.0, 0.04, 0.12, 0.08, 0.10, branch=+1)
    np.testing.assert_allclose(_rocker_angle(mech, 0.3), ref.theta4, atol=1e-10)


def test_a_tampered_mjcf_rewrite_is_not_loaded(tmpdir_of_test):
    """The rewritten MJCF was loaded as found: a changed body offset changed the model. The
    coupler's hinge A sits at pos="0.04 0 0" of the crank in models/mjcf/four_bar.xml."""
    cached = Path(load_mjcf(MJCF).urdf_path)
    assert cached.parent == _shared_folder(tmpdir_of_test)
    text = cached.read_text()
    tampered = text.replace('pos="0.04 0 0"', 'pos="0.06 0 0"', 1)
    assert tampered != text
    cached.write_text(tampered)
    again = load_mjcf(MJCF)
    assert Path(again.urdf_path).read_text() == text
    np.testing.assert_allclose(again.model.jointPlacements[again.model.getJointId("A")].translation,
                               [0.04, 0.0, 0.0], rtol=0, atol=rounding(0.04))


def test_a_link_in_place_of_a_cache_file_is_replaced_not_followed(tmpdir_of_test, tmp_path):
    """A symbolic link at the cache file's name is neither read nor written through."""
    text = "<robot name='x'/>\n"
    path = user_cache.cached_text("linkage", ".urdf", text)
    path.unlink()
    victim = tmp_path / "victim.txt"
    victim.write_text(text)  # even with the right content, a link is not trusted
    path.symlink_to(victim)
    assert user_cache.cached_text("linkage", ".urdf", text) == path
    assert not path.is_symlink() and path.read_text() == text and victim.read_text() == text
