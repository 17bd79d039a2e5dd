"""Extreme values and hostile map JSON: the library's own errors, never plain exceptions."""

from __future__ import annotations

import json
import re
import sys

import pytest

from spherewarp.errors import InvalidValueError
from spherewarp.maps import ExpMap, Lattes, Mobius, Power, map_from_json
from spherewarp.maps.elliptic import MAX_FITTED_DEGREE


@pytest.mark.parametrize(
    "matrix",
    [
        [[1e308, 0], [0, 1]],
        [[1e308, 1e308], [0, 1]],
        [[1e308j, 0], [0, 1]],
        [[1, 0], [0, 1e-320]],
        [[5e-324, 0], [0, 1]],
        [[1e-300, 0], [0, 1]],
    ],
)
def test_nearly_singular_matrices_give_a_bounded_message(matrix):
    with pytest.raises(InvalidValueError, match="singular in double precision") as err:
        Mobius(matrix)
    # the measure is scale-free: never a huge |det| from a tiny zoom
    assert "e+" not in str(err.value)


def test_huge_but_well_conditioned_matrices_are_fine():
    m = Mobius([[1e308, 1e308], [1e308, -1e308]])
    assert abs(m.matrix[0, 0] * m.matrix[1, 1] - m.matrix[0, 1] * m.matrix[1, 0] - 1) < 1e-12


def test_lattes_rational_fit_bound_is_checked():
    assert MAX_FITTED_DEGREE == 49
    Lattes("7")  # degree 49: the fit holds
    with pytest.raises(InvalidValueError, match="method='exact'") as info:
        Lattes("8")
    assert "--exact" in info.value.cli_message  # the command line's wording
    assert Lattes("8", method="exact").degree == 64
    with pytest.raises(InvalidValueError, match="<= 64"):
        Lattes("8+1j", method="exact")


@pytest.mark.parametrize(
    ("doc", "needle"),
    [
        ('{"kind": "expression"}', "missing field 'expr'"),
        ('{"kind": "droste", "rho": 0.1, "scale": 8}', "missing field 'center'"),
        ('{"kind": "power", "exponent": ' + "9" * 5000 + "}", "number too long"),
        ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
        (
            '{"kind": "composite", "maps": '
            + '[{"kind": "composite", "maps": ' * 5000
            + "[]"
            + "}]" * 5000
            + "}",
            "nested too deeply",
        ),
        ('{"kind": "mobius", "matrix": [[1e308, 0], [0, 1]]}', "singular"),
        ('{"kind": "os.system", "command": "true"}', "unknown map kind"),
        ('{"kind": "power", "exponent": "two"}', "power"),
    ],
)
def test_hostile_map_json_is_one_invalid_value_error(doc, needle):
    before = set(sys.modules)
    with pytest.raises(InvalidValueError, match=needle):
        map_from_json(doc)
    new = {m for m in set(sys.modules) - before if not m.startswith("spherewarp")}
    assert not new, new  # only the registered kinds' modules may be imported


def test_every_field_of_a_valid_document_can_be_missing_or_hostile():
    docs = [
        Mobius.zoom((30, 10), 2.0).to_dict(),
        {"kind": "droste", "center": [0, 0], "rho": 0.1, "scale": 8},
        Lattes(2).to_dict(),
    ]
    hostile = [None, "x", [], {}, [[1]], 1e308, -1e308, 10**30, {"kind": "mobius"}]
    for doc in docs:
        for key in doc:
            if key == "kind":
                continue
            variants = [{k: v for k, v in doc.items() if k != key}]
            variants += [{**doc, key: value} for value in hostile]
            for variant in variants:
                try:
                    map_from_json(json.dumps(variant))
                except InvalidValueError:
                    pass


@pytest.mark.parametrize("t", [30, 1000, 1e6, -1e300])
def test_a_power_out_of_range_says_so(t):
    with pytest.raises(InvalidValueError, match=re.escape(f"the power {t:g} of this map is out")):
        Mobius.zoom((0, 0), 4) ** t


@pytest.mark.parametrize("t", [1 + 1j, "2", True, None])
def test_a_power_that_is_not_a_real_number_is_a_type_error(t):
    from spherewarp.errors import InvalidTypeError

    with pytest.raises(InvalidTypeError, match="expected a real power"):
        Mobius.zoom((0, 0), 4) ** t


@pytest.mark.parametrize("cls", [Power, ExpMap])
def test_power_and_exp_refuse_a_million_copies_and_more(cls):
    with pytest.raises(InvalidValueError, match="at most 1e\\+06"):
        cls(1e308)
