"""One colour per link across every output: the colour a URDF paints a link's visuals
with (its `<material>`, inline or named at the top level) is the link's colour in the
curves (pinmech.model.display.colour_of), the polygons and the 3-D page's visuals; a URDF
without materials gets the palette everywhere. Expected colours are the ones written into
the test's own files, compared exactly (they pass through float32 in Pinocchio's visuals:
atol 1e-7)."""

from __future__ import annotations

import re

import numpy as np

import pinmech
from pinmech.model.display import PALETTE, colour_of, hex_colour
from pinmech.draw.pages import mechanism_visuals

from .conftest import MODELS, SCENES

#: Unusual colours: none is in the palette (crank named at the top level, coupler inline).
CRANK, COUPLER = (0.2, 0.9, 0.9), (0.7, 0.6, 0.05)


def _scene(tmp_path, urdf_text: str):
    (tmp_path / "four_bar.urdf").write_text(urdf_text)
    scene = (SCENES / "four_bar.toml").read_text().replace('urdf = "../four_bar.urdf"', 'urdf = "four_bar.urdf"')
    (tmp_path / "scene.toml").write_text(scene)
    return pinmech.Scene.load(tmp_path / "scene.toml")


def _visual_colours(mechanism) -> dict[int, np.ndarray]:
    visuals, _ = mechanism_visuals(mechanism)
    return {o.parentJoint: o.meshColor[:3] for o in visuals.geometryObjects if not o.name.startswith("sketch_")}


def test_a_urdfs_own_link_colours_are_used_by_curves_polygons_and_pages(tmp_path):
    text = (MODELS / "four_bar.urdf").read_text()
    text = text.replace('<color rgba="0.85 0.15 0.15 1"/>', f'<color rgba="{" ".join(map(str, CRANK))} 1"/>')
    text = text.replace('<material name="blue"/>', f'<material name="odd"><color rgba="{" ".join(map(str, COUPLER))} 1"/></material>')
    scene = _scene(tmp_path, text)
    analysis = pinmech.analyse(scene)
    mech = analysis.mechanism
    np.testing.assert_allclose([colour_of(mech, "crank"), colour_of(mech, "coupler")], [CRANK, COUPLER], atol=0)
    polygon = pinmech.velocity_polygon(analysis)
    assert (polygon.colours["crank"], polygon.colours["coupler"]) == (hex_colour(CRANK), hex_colour(COUPLER))
    page = _visual_colours(mech)
    crank, coupler = (mech.model.frames[mech.links[n]].parentJoint for n in ("crank", "coupler"))
    np.testing.assert_allclose([page[crank], page[coupler]], [CRANK, COUPLER], atol=1e-7)


def test_a_urdf_without_materials_gets_the_palette_everywhere(tmp_path):
    text = re.sub(r"<material[^>]*/>|<material[^>]*>.*?</material>", "", (MODELS / "four_bar.urdf").read_text(), flags=re.S)
    assert "material" not in text
    analysis = pinmech.analyse(_scene(tmp_path, text))
    mech = analysis.mechanism
    names = ["crank", "coupler", "rocker"]
    joints = [mech.model.frames[mech.links[n]].parentJoint for n in names]
    expected = [PALETTE[j - 1] for j in joints]  # the palette in the order of the joints
    np.testing.assert_allclose([colour_of(mech, n) for n in names], expected, atol=0)
    polygon = pinmech.velocity_polygon(analysis)
    assert [polygon.colours[n] for n in names if n in polygon.colours] == [
        hex_colour(c) for n, c in zip(names, expected) if n in polygon.colours]
    page = _visual_colours(mech)
    np.testing.assert_allclose([page[j] for j in joints], expected, atol=1e-7)


def test_an_mjcf_files_geom_colours_are_used_by_curves_and_pages(tmp_path):
    """An MJCF four-bar whose crank geom is orange (rgba) and whose coupler geom has no
    colour: the crank is MuJoCo's geom_rgba in the curves and on the page; the coupler,
    which the file does not colour (MuJoCo's default grey), takes the palette's colour in
    both, so the two outputs agree."""
    mujoco = __import__("pytest").importorskip("mujoco")
    text = (MODELS / "mjcf" / "four_bar.xml").read_text()
    assert 'rgba="0.85 0.15 0.15 1"' in text and 'rgba="0.15 0.35 0.85 1"' in text
    text = text.replace('rgba="0.85 0.15 0.15 1"', 'rgba="0.9 0.6 0.1 1"').replace(' rgba="0.15 0.35 0.85 1"', "")
    path = tmp_path / "four_bar.xml"
    path.write_text(text)
    compiled = mujoco.MjModel.from_xml_path(str(path))
    crank_rgba = compiled.geom_rgba[0][:3]  # the file's first geom is the crank's
    mech = pinmech.load_mjcf(path)
    np.testing.assert_allclose(colour_of(mech, "crank"), crank_rgba, atol=1e-7)  # float32 in MuJoCo
    pages = _visual_colours(mech)
    crank_joint = mech.model.frames[mech.links["crank"]].parentJoint
    coupler_joint = mech.model.frames[mech.links["coupler"]].parentJoint
    np.testing.assert_allclose(pages[crank_joint], crank_rgba, atol=1e-7)
    np.testing.assert_allclose(colour_of(mech, "coupler"), PALETTE[coupler_joint - 1], atol=0)
    np.testing.assert_allclose(pages[coupler_joint], PALETTE[coupler_joint - 1], atol=1e-7)
