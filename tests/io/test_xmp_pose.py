"""GPano pose (PoseHeadingDegrees, PosePitchDegrees, PoseRollDegrees): read, written, turned."""

from __future__ import annotations

import numpy as np
import pytest

from spherewarp.errors import InvalidValueError
from spherewarp.io import GPano, gpano_xmp, parse_gpano, read_image, write_image

_ELEMENTS = """<x:xmpmeta xmlns:x="adobe:ns:meta/"><rdf:RDF
  xmlns:rdf="http://www.w3.org/1999/02/22-rdf-syntax-ns#">
  <rdf:Description xmlns:GPano="http://ns.google.com/photos/1.0/panorama/">
    <GPano:FullPanoWidthPixels>400</GPano:FullPanoWidthPixels>
    <GPano:FullPanoHeightPixels>200</GPano:FullPanoHeightPixels>
    <GPano:PoseHeadingDegrees>123.5</GPano:PoseHeadingDegrees>
    <GPano:PosePitchDegrees>-2</GPano:PosePitchDegrees>
    <GPano:PoseRollDegrees>1.25</GPano:PoseRollDegrees>
  </rdf:Description></rdf:RDF></x:xmpmeta>"""


def test_pose_parsed_from_elements_and_written_back():
    g = parse_gpano(_ELEMENTS)
    assert (g.pose_heading, g.pose_pitch, g.pose_roll) == (123.5, -2.0, 1.25)
    assert parse_gpano(gpano_xmp(g)) == g


def test_no_pose_written_when_unset():
    xmp = gpano_xmp(GPano.full_sphere(8, 4))
    assert "Pose" not in xmp
    assert not parse_gpano(xmp).has_pose


def test_pose_is_normalised_and_checked():
    g = GPano(full_width=8, full_height=4, pose_heading=-30, pose_roll=190)
    assert (g.pose_heading, g.pose_roll) == (330.0, -170.0)
    with pytest.raises(InvalidValueError):
        GPano(full_width=8, full_height=4, pose_pitch=91)
    with pytest.raises(InvalidValueError):
        parse_gpano(_ELEMENTS.replace(">123.5<", ">north<"))


def test_turned():
    level = GPano(full_width=8, full_height=4, pose_heading=350.0)
    assert level.turned(30).pose_heading == 20.0
    tilted = GPano(full_width=8, full_height=4, pose_heading=10.0, pose_roll=2.0)
    assert tilted.turned(30) is None
    assert tilted.turned(0) == tilted
    assert not tilted.without_pose().has_pose


def test_pose_survives_placement_of_a_crop(tmp_path):
    crop = GPano(full_width=64, full_height=32, cropped_height=16, cropped_top=8, pose_heading=42.0)
    write_image(tmp_path / "c.png", np.zeros((16, 64, 3), np.uint8), gpano=crop)
    data = read_image(tmp_path / "c.png")
    assert data.pixels.shape[:2] == (32, 64)
    assert not data.gpano.is_cropped and data.gpano.pose_heading == 42.0
