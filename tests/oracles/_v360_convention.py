"""The rotation that ffmpeg's ``v360=e:e:yaw=Y:pitch=P:roll=R`` applies, in spherewarp's frame.

spherewarp convention (W x H equirect, W = 2H, continuous pixel coords with
pixel centres at half-integers):

    lon = 2*pi*x/W - pi,   lat = pi/2 - pi*y/H
    d   = (cos lat cos lon, cos lat sin lon, sin lat)
    +x = front (image centre), +y = lon +90 deg (right of centre), +z = up.

Result (default ``rorder=ypr``), derived from libavfilter/vf_v360.c and
confirmed empirically (least-squares fit of the sampling map, agreement
~1e-4 per matrix entry, i.e. float32 precision)::

    out(d) = in(R d),   R = Rz(yaw) @ Ry(-pitch) @ Rx(-roll)

with the ordinary right-handed rotations Rx, Ry, Rz about our +x, +y, +z.

Meaning of positive angles (what the output shows):

* yaw   > 0: the view turns RIGHT. The input direction at lon = +yaw
  (right of the old centre) comes to the output image centre; content
  shifts left in the image.
* pitch > 0: the view tilts UP. The input direction at lat = +pitch
  (above the old centre) comes to the output image centre; content moves
  down in the image.
* roll  > 0: the view rolls clockwise about the forward (+x) axis as seen
  by the viewer, i.e. the camera's right side dips: the output's right
  horizon (lon +90, lat 0) shows input lat = -roll, and the displayed
  scene appears rotated counter-clockwise.

Why: ffmpeg's internal frame is f = (X, Y, Z) = (y, -z, x) in ours (a
reflection, det -1). Its matrix is Yaw @ Pitch @ Roll (in rorder) with Yaw
about f-Y, Pitch about f-X, Roll about f-Z, applied as in_f = M @ out_f.
Conjugating by the reflection flips the rotation sense, and f-Y = -z, so:
yaw -> Rz(+yaw), pitch -> Ry(-pitch), roll -> Rx(-roll).

ffmpeg's pixel mapping (libavfilter 11, ``equirect`` both sides): the
OUTPUT uses pixel centres, lon = ((2i+1)/W - 1)*pi, matching ours exactly;
the INPUT is sampled at index  u = (lon/pi + 1)/2 * (W - 1)  (and
v = (1 - 2 lat/pi)/2 * (H - 1)), i.e. input sample k sits at
lon = (2k/(W-1) - 1)*pi: edge-to-edge ("align corners"), not at centres.
In our continuous coordinates the input is read at
x_ff = x * (W-1)/W + 0.5 instead of x: an offset of +0.5 px at the left
edge, 0 at the image centre, -0.5 px at the right edge (same vertically).
Measured: identity v360 at W=64 reads input index u = (i + 0.5) * 63/64.
Rows are clamped at the poles; columns wrap (mod W).
"""

from __future__ import annotations

import numpy as np


def _rx(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _ry(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rz(t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def v360_matrix(yaw_deg: float, pitch_deg: float, roll_deg: float) -> np.ndarray:
    """R such that ``v360=e:e:yaw:pitch:roll`` (rorder=ypr) gives out(d) = in(R d).

    R = Rz(yaw) @ Ry(-pitch) @ Rx(-roll), float64, orthonormal, det +1.
    Positive yaw turns the view right (lon = +yaw comes to the centre);
    positive pitch tilts it up (lat = +pitch comes to the centre); positive
    roll rolls the view clockwise (the output's right horizon shows input
    lat = -roll; the scene appears rotated counter-clockwise).
    """
    y, p, r = np.radians([yaw_deg, pitch_deg, roll_deg])
    return _rz(y) @ _ry(-p) @ _rx(-r)
