"""An offline page embeds the model's own meshes only: a file outside its package (`../`,
absolute, `file://`, `package://../..`, a link pointing out) is left out, and said."""

from __future__ import annotations

import base64
import importlib.util
import os
import re

import pytest

from pinmech.cli import main

pytestmark = pytest.mark.skipif(importlib.util.find_spec("meshcat") is None, reason='needs pip install "pinmech[viz]"')

OWN = "v 0.111 0.222 0.333\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"  # marker vertex of the package's mesh
SECRET = "v 0.777 0.888 0.999\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"  # ... and of a file outside it
OUTSIDE = ["../../secret/s.obj", "{root}/secret/s.obj", "file://{root}/secret/s.obj", "package://../../secret/s.obj",
           "../meshes/link.obj"]  # the last is a symbolic link to the secret file


@pytest.fixture
def layout(tmp_path):
    """A ROS-style package (pkg/package.xml, pkg/urdf, pkg/meshes) next to a secret folder."""
    for folder in ("pkg/urdf", "pkg/meshes", "secret"):
        (tmp_path / folder).mkdir(parents=True)
    (tmp_path / "pkg" / "package.xml").write_text("<package/>")
    (tmp_path / "pkg" / "meshes" / "own.obj").write_text(OWN)
    (tmp_path / "secret" / "s.obj").write_text(SECRET)
    os.symlink(tmp_path / "secret" / "s.obj", tmp_path / "pkg" / "meshes" / "link.obj")
    meshes = ["../meshes/own.obj", "package://pkg/meshes/own.obj"] + [m.format(root=tmp_path) for m in OUTSIDE]
    visuals = "".join(f'<visual><geometry><mesh filename="{m}"/></geometry></visual>' for m in meshes)
    (tmp_path / "pkg" / "urdf" / "r.urdf").write_text(
        f'<?xml version="1.0"?><robot name="r"><link name="base">{visuals}'
        '<visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link><link name="arm"/>'
        '<joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>')
    scene = tmp_path / "s.toml"
    scene.write_text('urdf = "pkg/urdf/r.urdf"\n[drivers.j]\nangle = "0 deg"\n')
    return scene


def _embedded(page: str) -> bytes:
    return b"".join(base64.b64decode(b) for b in re.findall(r'command\("([^"]*)"\)', page))


def test_a_page_embeds_the_package_meshes_only_and_says_what_it_left_out(layout, tmp_path, capsys):
    page = tmp_path / "p.html"
    assert main(["snapshot", str(layout), "-o", str(page)]) == 0
    data = _embedded(page.read_text())
    assert b"0.111 0.222 0.333" in data  # the package's own mesh is drawn
    assert b"0.777 0.888 0.999" not in data  # no byte of the file outside it
    err = capsys.readouterr().err
    assert err.count("left out of the drawing: it is outside the model's package") == len(OUTSIDE)


def test_package_visuals_lists_the_files_left_out(layout):
    import pinocchio as pin

    from pinmech.draw import package_visuals

    urdf = layout.parent / "pkg" / "urdf" / "r.urdf"
    visuals, skipped = package_visuals(urdf, pin.buildModelFromUrdf(str(urdf)))
    kept = sorted(os.path.realpath(o.meshPath) for o in visuals.geometryObjects if os.sep in o.meshPath)
    assert kept == [str(layout.parent / "pkg" / "meshes" / "own.obj")] * 2
    assert len(skipped) == len(OUTSIDE) and all("(link base)" in s for s in skipped)
    assert any(o.meshPath == "BOX" for o in visuals.geometryObjects)  # shapes have no file: kept
