"""Property tests of the scene schema (hypothesis): any table a user could write into a scene file,
with the real keys and values of every type, is a scene or one line naming a key path (ValueError),
never another exception; and the files of an accepted scene's outputs never collide."""

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from validation.scenes.schema import OUTPUT_KINDS, _TABLES, scene_from_mapping

FAST = settings(max_examples=80, deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.too_slow])

SCALAR = st.one_of(st.integers(-5, 5000), st.floats(allow_nan=True, allow_infinity=True), st.booleans(),
                   st.sampled_from(["A", "B", "a", "pmma-1.89", "frictionless", "sticking", "coulomb", "fem",
                                    "appendix-a", "paper", "profile", "coupled", "coarse", "medium", "none",
                                    "default", "air", "water", "", "x", "../x.toml"]))
VALUE = st.one_of(SCALAR, st.lists(SCALAR, max_size=4))
TABLES = st.fixed_dictionaries({}, optional={name: st.dictionaries(st.sampled_from([*keys, "unknown"]), VALUE,
                                                                   max_size=3)
                                             for name, keys in _TABLES.items()})
OUTPUT = st.dictionaries(st.sampled_from(["kind", "name", "u_mm", "figure", "F1_N", "frames", "field", "view"]),
                         st.one_of(st.sampled_from([*OUTPUT_KINDS, "lifetime_vs_force", "F0_vs_u"]), SCALAR),
                         max_size=4)
SWEEP = st.dictionaries(st.sampled_from(["key", "values", "other"]),
                        st.one_of(st.sampled_from(["loads.kappa", "cup.preset", "surface.preset"]), VALUE),
                        max_size=3)


@FAST
@given(tables=TABLES, outputs=st.lists(OUTPUT, max_size=3), sweep=st.one_of(st.none(), SWEEP))
def test_random_scenes_parse_or_refuse_in_one_line(tables, outputs, sweep, tmp_path_factory):
    data = dict(tables)
    data["outputs"] = [{"kind": "lifetimes"}, *outputs]     # one valid output: most draws reach the tables
    if sweep is not None:
        data["sweep"] = sweep
    base = tmp_path_factory.mktemp("scene")
    try:
        scene_from_mapping(data, base=base, source="s.toml")
    except ValueError as exc:
        message = str(exc)
        assert message and "\n" not in message.strip()
