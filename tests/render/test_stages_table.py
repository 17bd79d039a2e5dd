"""The table of compiled stages (``spherewarp.render.stages``): layout, packing, exports."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from spherewarp.maps import Droste, ExpMap, Lattes, Mobius, Power, Rational, Schottky
from spherewarp.render import fast, stages

KERNELS = Path(stages.__file__).with_name("_kernels.py")

MAPS = {
    "mobius": Mobius.zoom((30, 10), 2.5),
    "power": Power(3, branch_points=((30, 20), (-100, -10))),
    "exp": ExpMap(4),
    "rational": Rational([1, 0, 0.3j], [0.5, 1, 2]),
    "lattes": Lattes((2, 1)),
    "droste": Droste((30, 20), np.log(0.3) + 0.1 * np.cos(np.arange(16)), 3.0, phase=0.3),
    "schottky": Schottky.from_disk_pairs([((0, 0, 20), (180, 0, 20))], phase=0.25),
    "schottky_mask": None,  # made from a mask below
}


def _schottky_mask():
    from spherewarp.maps.schottky import Cap, MaskRegions, cap_from_mask, generator_between

    mask = np.zeros((18, 36, 3), np.uint8)
    mask[8:10, 17:19] = (255, 0, 0)
    cap = cap_from_mask(mask, (1, 0, 0), inside=True)
    s = Schottky([(cap, generator_between(cap, Cap(180, 0, 10)))], phase=0.5)
    return s.with_mask_regions(MaskRegions(mask, [(1, 0, 0)]))


MAPS["schottky_mask"] = _schottky_mask()


def test_codes_are_unique_and_in_order():
    assert [s.code for s in stages.STAGES] == list(range(1, len(stages.STAGES) + 1))
    for s in stages.STAGES:
        assert stages.BY_NAME[s.name] is s
        assert stages.BY_CODE[s.code] is s
        assert len(set(s.fields)) == len(s.fields)


def test_jump_kinds_come_from_the_table():
    assert fast.JUMP_KINDS == {s.name for s in stages.STAGES if s.has_jumps}
    assert sorted(fast.jump_codes()) == sorted(stages.BY_NAME[k].code for k in fast.JUMP_KINDS)
    assert {"droste", "exp", "schottky"} <= fast.JUMP_KINDS
    assert "mobius" not in fast.JUMP_KINDS


@pytest.mark.parametrize("name", list(MAPS))
def test_every_map_packs_rows_the_table_accepts(name):
    """Each stage a map returns passes the table's check, and unpack/pack is the identity."""
    found = False
    for kind, row in MAPS[name].kernel_stages():
        st = stages.BY_NAME[kind]
        assert st.problem(row) is None, (kind, st.problem(row))
        again = st.pack(**st.unpack(row))
        assert np.array_equal(again, row)
        found |= kind == name or (name == "lattes" and kind == "rational")
    assert found


def test_pack_refuses_missing_and_unknown_fields():
    with pytest.raises(TypeError, match="missing \\['near', 'cap'\\]"):
        stages.BY_NAME["exp"].pack(lam=1.0)
    with pytest.raises(TypeError, match="unknown field\\(s\\) \\['bogus'\\]"):
        stages.BY_NAME["power"].pack(m=2, bogus=1)
    with pytest.raises(TypeError, match="missing \\['rho'\\]"):
        st = stages.BY_NAME["droste"]
        st.pack(**{f: 1.0 for f in st.fields})
    with pytest.raises(ValueError, match="does not fit"):
        stages.BY_NAME["power"].unpack(np.zeros(2))


def test_complex_tails_become_pairs():
    row = stages.BY_NAME["rational"].pack(degree=1, coefficients=np.array([1, 2j, 3, 4 + 5j]))
    assert row.tolist() == [1, 1, 0, 0, 2, 3, 0, 4, 5]


@pytest.mark.parametrize(
    ("kind", "row", "words"),
    [
        ("power", [0.0], "non-zero integer"),
        ("power", [2.0, 1.0], "expected 1 floats"),
        ("exp", [-1.0, 0.1, 1.0], "positive"),
        ("exp", [1.0, np.nan, 1.0], "finite"),
        ("rational", [1.0, 1, 0, 0, 0], "degree"),
        ("droste", [2.0] + [1.0] * 9, "rho samples"),
        ("schottky", [1.0, 10.0] + [0.0] * 20, "2 moves"),
        ("schottky", [1.0, -1.0] + [0.0] * 40, "non-negative"),
        ("mobius", [0.0] * 8, "singular"),
    ],
)
def test_bad_rows_are_named(kind, row, words):
    assert words in stages.BY_NAME[kind].problem(np.array(row))


def test_offsets_and_constants_agree():
    c = stages.constants()
    for s in stages.STAGES:
        assert c[f"STAGE_{s.name.upper()}"] == s.code
        for i, f in enumerate(s.fields):
            assert s.offset(f) == i == c[f"{s.name.upper()}_{f.upper()}"]
        if s.tail is not None:
            assert s.offset(s.tail) == len(s.fields)
    for k, v in c.items():
        assert getattr(stages, k) == v  # module constants, for the kernels
    with pytest.raises(KeyError):
        stages.BY_NAME["power"].offset("lam")
    assert c["SCHOTTKY_MOVES_SIZE"] == len(stages.SCHOTTKY_RECORD)


def test_glsl_header_defines_every_constant():
    lines = stages.glsl_header().splitlines()
    assert lines[0].startswith("//")
    defs = {}
    for line in lines[1:]:
        m = re.fullmatch(r"#define ([A-Z][A-Z0-9_]*) (\d+)", line)
        assert m, line
        defs[m[1]] = int(m[2])
    assert defs == stages.constants()


def test_json_has_the_stable_names():
    table = json.loads(stages.as_json())
    assert [s["name"] for s in table["stages"]] == [s.name for s in stages.STAGES]
    for rec, s in zip(table["stages"], stages.STAGES, strict=True):
        assert rec["code"] == s.code
        assert rec["fields"] == list(s.fields)
        assert rec["tail"] == s.tail
        assert rec["has_jumps"] == s.has_jumps
    assert table["stages"][0]["args"][:2] == ["a_re", "a_im"]


def test_kernels_know_this_table():
    """numba caches the kernels by _kernels.py alone: its fingerprint must be the table's, so
    that changing the table touches (and recompiles) that file."""
    m = re.search(r'_TABLE_FINGERPRINT = "([0-9a-f]+)"', KERNELS.read_text(encoding="utf-8"))
    assert m and m[1] == stages.fingerprint()


def test_the_table_does_not_import_numba():
    code = "import sys, spherewarp.render.stages; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_mobius_lowers_to_its_lorentz_matrix():
    m = Mobius.zoom((30, 10), 2.0) @ Mobius.rotation((5, 5), 20)
    ((_, packed),) = m.kernel_stages()
    row = stages.BY_NAME["mobius"].kernel_row(packed)
    mat = m.matrix / np.sqrt(np.linalg.det(m.matrix))
    assert np.allclose(row.reshape(4, 4), stages.lorentz_from_sl2(mat), atol=1e-12)
    spec = fast.kernel_spec(m)
    assert spec is not None and np.array_equal(spec.params[0, :16], row)
