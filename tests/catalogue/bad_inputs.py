"""The catalogue of bad inputs (issue 16): each one is refused with exit status 2, one line on
stderr naming the field, and no file written. Plain data, read by tests/test_catalogue.py and by
`python -m tests.catalogue.report` (the table in docs/reliability.md).

A case is (category, argv, files, expected): `argv` may name {d}, the test's directory; `files`
maps a file name in {d} to its content (str, or bytes for binary input); `expected` is a
substring of the one-line error.
"""

from __future__ import annotations

from pathlib import Path

GOOD_UC = "p_over_E,u_c_m\n1e-4,2e-6\n1e-3,1e-6\n1e-2,5e-7\n1e-1,1e-7\n"
GOOD_CURVE = "u_mm,h_mm,F0_N\n0,9,0\n1,8,2.5\n2,7,4\n3,6,5\n4,5,5.5\n5,4,6\n6,3,7\n7,2,9\n8,1,14\n"
PSD_ROWS = "".join(f"{q:g},{1e-26 * (q / 1e4) ** -3.6:g}\n" for q in (3e2, 1e3, 3e3, 1e4, 3e4, 1e5, 3e5, 1e6))
LIFE = ["lifetime", "--out", "{d}/out"]
STIFF = ["stiffness", "--fidelity", "coarse", "--out", "{d}/out/c.csv"]
UC = ["uc", "--out", "{d}/out/uc.csv"]
SWEEP = ["sweep", "{d}/s.toml", "--out", "{d}/out"]

CASES: list[tuple[str, list[str], dict, str]] = []


def case(category: str, argv: list[str], expected: str, **files) -> None:
    CASES.append((category, argv, files, expected))


# ------------------------------------------------------------------ numeric command-line options
for opt, value, expected in [
    ("--force", "-1", "--force: pull force must be > 0 N"),
    ("--force", "0", "--force: pull force must be > 0 N"),
    ("--force", "nan", "--force: pull force must be > 0 N"),
    ("--force", "inf", "--force: pull force must be > 0 N"),
    ("--force", "ten", "argument --force: invalid float value: 'ten'"),
    ("--E-MPa", "0", "--E-MPa: Young's modulus must be > 0 MPa"),
    ("--E-MPa", "-4", "--E-MPa: Young's modulus must be > 0 MPa"),
    ("--E-MPa", "nan", "--E-MPa: Young's modulus must be > 0 MPa"),
    ("--E-MPa", "4e6", "--E-MPa = 4e+06: did you give Pa?"),
    ("--E-MPa", "0.001", "--E-MPa = 0.001: did you give GPa?"),
    ("--d0-mm", "0", "--d0-mm: wall thickness must be > 0 mm"),
    ("--d0-mm", "nan", "--d0-mm: wall thickness must be > 0 mm"),
    ("--kappa", "0", "--kappa: stiffness factor must be > 0"),
    ("--kappa", "inf", "--kappa: stiffness factor must be > 0"),
    ("--kappa", "-2", "--kappa: stiffness factor must be > 0"),
    ("--T-K", "-5", "T_K: must be > 0"),
    ("--T-K", "nan", "T_K: must be > 0"),
    ("--p-a-Pa", "0", "p_a_Pa: ambient pressure must be > 0 Pa"),
    ("--p-a-Pa", "inf", "p_a_Pa: ambient pressure must be > 0 Pa"),
    ("--t-max-s", "0", "--t-max-s, --rtol: need t_max > 0 s and 0 < rtol < 0.01"),
    ("--rtol", "0.5", "--t-max-s, --rtol: need t_max > 0 s and 0 < rtol < 0.01"),
    ("--rtol", "nan", "--t-max-s, --rtol: need t_max > 0 s and 0 < rtol < 0.01"),
    ("--r-start-mm", "3", "r_start_mm: start radius must be in (r0, r1) = (5, 19) mm, got 3"),
    ("--r-start-mm", "nan", "r_start_mm: start radius must be in (r0, r1) = (5, 19) mm"),
    ("--phi0-s", "0", "phi0_s: measurement contact time must be > 0 s"),
    ("--liquid-viscosity-Pa-s", "0", "liquid_viscosity_Pa_s: must be > 0"),
]:
    case("CLI option", LIFE + [opt, value], expected)
case("CLI option", LIFE + ["--l0-mm", "1"], "l0_mm, l1_mm: give both strip widths of eq (5) or neither")
case("CLI option", LIFE + ["--l0-mm", "0", "--l1-mm", "1"], "l0_mm: contact-strip width must be > 0 mm")
case("CLI option", LIFE + ["--surface", "pmma-1.89", "--gamma", "-1"], "gamma")
case("CLI option", LIFE + ["--surface", "pmma-1.89", "--a-c", "1.5"], "a_c")
case("CLI option", LIFE + ["--surface", "pmma-1.89", "--nu", "0.7"], "nu")
case("CLI option", LIFE + ["--surface", "glass"], "surface: unknown preset 'glass'")
for opt, value, expected in [
    ("--E-MPa", "4e6", "E_MPa = 4e+06: did you give Pa?"),
    ("--E-MPa", "nan", "E_MPa: Young's modulus must be > 0 MPa"),
    ("--nu", "0.6", "nu"),
    ("--u-max-mm", "0", "u_max_mm"),
    ("--u-max-mm", "50", "u_max_mm: plate displacement must be in (0, h1]"),
    ("--u-max-mm", "nan", "u_max_mm"),
    ("--fidelity", "ultra", "argument --fidelity: invalid choice: 'ultra'"),
    ("--cup", "C", "argument --cup: invalid cup 'C'"),
]:
    case("CLI option", STIFF + [opt, value], expected)
case("CLI option", STIFF + ["--formulation", "displacement", "--nu", "0.499"],
     "nu: with the displacement formulation Poisson's ratio must be <= 0.495")
case("CLI option", STIFF + ["--contact", "coulomb"], "friction: --contact coulomb needs --friction MU, in [0, 100]")
case("CLI option", STIFF + ["--contact", "coulomb", "--friction", "-0.2"], "friction: Coulomb's friction coefficient must be in [0, 100]")
case("CLI option", STIFF + ["--contact", "coulomb", "--friction", "nan"], "friction: Coulomb's friction coefficient must be in [0, 100]")
case("CLI option", STIFF + ["--friction", "0.3"], "friction: applies to --contact coulomb only")
for command in (["example", "--out", "{d}/out"], ["suction", "--out", "{d}/out/s.json"]):
    case("CLI option", command + ["--contact", "coulomb"], "friction: --contact coulomb needs --friction MU, in [0, 100]")
    case("CLI option", command + ["--contact", "sticking", "--friction", "0.5"], "friction: applies to --contact coulomb only")
case("CLI option", ["stiffness", "--out", "{d}/c.txt"], "out: the stiffness curve must be a .csv file")
case("CLI option", STIFF + ["--fields-out", "{d}/f.png"], "fields_out: must end in .vtu or .vtk")
case("CLI option", UC + ["--surface", "pmma-1.89", "--E-MPa", "0"], "E")
case("CLI option", UC + ["--surface", "pmma-1.89", "--p-kPa", "-5"], "p")
case("CLI option", ["sweep", "{d}/s.toml", "--out", "{d}/out", "--workers", "0"], "--workers: must be in [1, 256]",
     **{"s.toml": "[base]\n"})

# ------------------------------------------------------------------ files that cannot be read
for opt, field in (("--stiffness", "stiffness"), ("--uc-table", "uc-table"), ("--relaxation", "relaxation"),
                   ("--psd", "psd"), ("--line-scan", "line scan")):
    case("unreadable file", LIFE + [opt, "{d}/missing.csv"], "no such file")
    case("unreadable file", LIFE + [opt, "{d}/empty.csv"], field, **{"empty.csv": ""})
    case("unreadable file", LIFE + [opt, "{d}/binary.csv"], field, **{"binary.csv": bytes(range(256)) * 4})
    case("unreadable file", LIFE + [opt, "{d}/latin1.csv"], field,
         **{"latin1.csv": "u_mm,F0_N\n0,0\n1,2\n".encode() + b"\xe9\xff\n"})
case("unreadable file", ["stiffness", "--geometry", "{d}/missing.toml", "--out", "{d}/out/c.csv"], "geometry: no such file")
case("unreadable file", ["stiffness", "--geometry", "{d}/g.toml", "--out", "{d}/out/c.csv"], "geometry: cannot parse",
     **{"g.toml": "r1_mm = = 3\n"})
case("unreadable file", ["stiffness", "--geometry", "{d}/g.toml", "--out", "{d}/out/c.csv"], "geometry:",
     **{"g.toml": b"\xff\xfe\x00r1_mm"})
case("unreadable file", ["stiffness", "--mesh", "{d}/missing.msh", "--out", "{d}/out/c.csv"], "mesh")
case("unreadable file", ["stiffness", "--mesh", "{d}/junk.msh", "--out", "{d}/out/c.csv"], "mesh", **{"junk.msh": "not a mesh\n"})
case("unreadable file", SWEEP, "sweep: no such file")
case("unreadable file", SWEEP, "sweep: cannot parse", **{"s.toml": "[base\n"})

# ------------------------------------------------------------------ CSV contents
for label, text, expected in [
    ("missing column", "u_mm,h_mm\n0,9\n1,8\n", "stiffness: '{d}/c.csv' lacks the required column 'F0_N'"),
    ("misnamed column", "u_mm,h_mm,F0\n0,9,0\n1,8,2\n", "stiffness: unknown column(s) ['F0']"),
    ("non-numeric cell", "u_mm,h_mm,F0_N\n0,9,0\n1,8,two\n", "stiffness: '{d}/c.csv' has a non-numeric entry"),
    ("NaN cell", "u_mm,h_mm,F0_N\n0,9,0\n1,8,nan\n2,7,3\n", "F0_N: contains NaN or infinite values"),
    ("unsorted u", "u_mm,h_mm,F0_N\n0,9,0\n2,7,3\n1,8,2\n", "u_m: displacements must be strictly increasing"),
    ("duplicate u", "u_mm,h_mm,F0_N\n0,9,0\n1,8,2\n1,8,2\n", "u_m: displacements must be strictly increasing"),
    ("negative width", "u_mm,h_mm,F0_N,l_mm\n0,9,0,1\n1,8,2,-1\n", "l_m: must be >= 0"),
    ("h1 not constant", "u_mm,h_mm,F0_N\n0,9,0\n1,7,2\n", "u_mm + h_mm is not constant"),
    ("one row", "u_mm,h_mm,F0_N\n0,9,0\n", "u_m: a stiffness curve needs at least 2 samples"),
    ("ragged rows", "u_mm,h_mm,F0_N\n0,9,0\n1,8\n", "stiffness"),
]:
    case(f"stiffness CSV: {label}", LIFE + ["--stiffness", "{d}/c.csv"], expected, **{"c.csv": text})
case("stiffness CSV: mixed units", LIFE + ["--stiffness", "{d}/c.csv"], "has h1 = 0.009 mm but cup A (Table 1) has h1",
     **{"c.csv": "u_mm,h_mm,F0_N\n0,0.009,0\n0.001,0.008,2\n0.002,0.007,3\n"})
for label, text, expected in [
    ("missing column", "p_over_E\n1e-3\n", "uc-table: '{d}/u.csv' must start with the header 'p_over_E,u_c_m'"),
    ("negative u_c", "p_over_E,u_c_m\n1e-3,1e-6\n1e-2,-1e-7\n", "u_c_m: must be finite and >= 0"),
    ("NaN u_c", "p_over_E,u_c_m\n1e-3,1e-6\n1e-2,nan\n", "u_c_m: must be finite and >= 0"),
    ("unsorted p", "p_over_E,u_c_m\n1e-2,1e-7\n1e-3,1e-6\n", "p_over_E: must be finite, > 0 and strictly increasing"),
    ("duplicate p", "p_over_E,u_c_m\n1e-3,1e-6\n1e-3,1e-7\n", "p_over_E: must be finite, > 0 and strictly increasing"),
    ("one row", "p_over_E,u_c_m\n1e-3,1e-6\n", "p_over_E: a u_c table needs at least 2 rows"),
    ("zero not trailing", "p_over_E,u_c_m\n1e-3,1e-6\n1e-2,0\n1e-1,1e-7\n", "u_c_m: a sealed (0) row may only be followed by sealed rows"),
    ("in micrometres", "p_over_E,u_c_m\n1e-3,1.2\n1e-2,0.68\n", "u_c_m at p_over_E = 0.001 = 1.2: did you give um or nm?"),
    ("non-numeric", "p_over_E,u_c_m\n1e-3,1e-6\n1e-2,small\n", "uc-table: '{d}/u.csv' has a non-numeric entry"),
]:
    case(f"u_c CSV: {label}", LIFE + ["--uc-table", "{d}/u.csv"], expected, **{"u.csv": text})
for label, text, expected in [
    ("missing column", "q_per_m\n1e3\n", "psd file {d}/p.csv: first line must be the header 'q_per_m,C_m4'"),
    ("negative C", "q_per_m,C_m4\n" + PSD_ROWS.replace("e-", "e-", 1).replace(",", ",-", 1), "C"),
    ("NaN C", "q_per_m,C_m4\n1e3,nan\n1e4,1e-30\n1e5,1e-33\n", "C"),
    ("unsorted q", "q_per_m,C_m4\n1e4,1e-30\n1e3,1e-28\n1e5,1e-33\n", "q"),
    ("two rows", "q_per_m,C_m4\n1e3,1e-28\n1e4,1e-30\n", "psd file {d}/p.csv: need at least 3 rows"),
    ("in micrometre units", "q_per_m,C_m4\n" + "".join(f"{q * 1e-6:g},{c * 1e24:g}\n" for q, c in (
        (3e2, 1e-17), (1e3, 1e-19), (1e4, 1e-22), (1e5, 1e-26), (1e6, 1e-30))), "did you give um"),
]:
    case(f"PSD CSV: {label}", LIFE + ["--psd", "{d}/p.csv"], expected, **{"p.csv": text})
for label, text, expected in [
    ("too short", "x_um,z_um\n" + "".join(f"{i},{i % 3}\n" for i in range(20)), "need at least 64 points, got 20"),
    ("bad unit", "x_in,z_in\n" + "".join(f"{i},{i % 3}\n" for i in range(100)), "header must be x_<unit>,z_<unit>"),
    ("gap", "x_um,z_um\n" + "".join(f"{i if i < 50 else i + 10},{i % 3}\n" for i in range(100)), "uniformly spaced"),
    ("non-numeric", "x_um,z_um\n" + "".join(f"{i},{'a' if i == 7 else i % 3}\n" for i in range(100)), "every row needs two numbers"),
    ("NaN height", "x_um,z_um\n" + "".join(f"{i},{'nan' if i == 7 else i % 3}\n" for i in range(100)),
     "row 9: x and z must be finite"),
]:
    case(f"line scan: {label}", LIFE + ["--line-scan", "{d}/s.csv"], expected, **{"s.csv": text})
for label, text, expected in [
    ("missing column", "t_s\n1\n", "relaxation: '{d}/r.csv' must start with the header 't_s,E_Pa'"),
    ("negative modulus", "t_s,E_Pa\n1,4e6\n10,-1\n", "E"),
    ("unsorted time", "t_s,E_Pa\n10,3e6\n1,4e6\n", "t"),
]:
    case(f"relaxation CSV: {label}", LIFE + ["--relaxation", "{d}/r.csv"], expected, **{"r.csv": text})

# ------------------------------------------------------------------ geometry files
GEO = ["stiffness", "--geometry", "{d}/g.toml", "--out", "{d}/out/c.csv"]
for label, text, expected in [
    ("unknown key", "r1_mm = 25\nangle = 40\n", "g.toml: unknown key(s) ['angle']"),
    ("wrong type", "r1_mm = \"25\"\n", "g.toml: r1_mm must be a number"),
    ("rim inside the plate", "r0_mm = 10\nr1_mm = 8\n", "r1_mm: rim radius must be > r0"),
    ("cone angle", "alpha_deg = 95\n", "alpha_deg: cone angle must be in (0, 90) degrees"),
    ("negative thickness", "[thickness]\nr_mm = [5, 19]\nd_mm = [2, -0.5]\n", "thickness: wall thickness must be > 0 mm"),
    ("thickness table short", "[thickness]\nr_mm = [5, 10, 12]\nd_mm = [2, 1, 0.5]\n", "thickness: the table covers r in [5, 12] mm"),
    ("thickness keys", "[thickness]\nr = [5, 19]\nd_mm = [2, 1]\n", "thickness must be a table with exactly the keys r_mm and d_mm"),
    ("unsorted thickness table", "[thickness]\nr_mm = [5, 12, 10, 19]\nd_mm = [2, 1, 1, 0.5]\n",
     "thickness: table radii r_mm must be strictly increasing"),
    ("one thickness point", "[thickness]\nr_mm = [5]\nd_mm = [2]\n", "thickness: a table needs >= 2 matching (r, d) pairs"),
    # a wall that crosses itself or the axis cannot be written in this format: the wall is offset
    # along the cavity surface's normal (or vertically) by d > 0, a graph over the cavity line
    # (fem/geometry.py); the self-intersection check there is a safety net
    ("radii in micrometres", "r0_mm = 5000\nr1_mm = 19000\n[thickness]\nr_mm = [5000, 19000]\nd_mm = [2500, 450]\n",
     "r0_mm = 5000: did you give um?"),
    ("steep tube", "alpha_deg = 85\n", "alpha_deg = 85 is outside 5 .. 80 deg"),
    ("slender wall", "r1_mm = 50\nalpha_deg = 45\n[thickness]\nr_mm = [5, 50]\nd_mm = [0.1, 0.1]\n", "slenderness"),
    ("thickness convention", "thickness_convention = \"oblique\"\n", "thickness_convention: must be one of normal, vertical"),
    # the [contact] table (fem.interface): the interface with the plane
    ("negative friction", "[contact]\nlaw = \"coulomb\"\nfriction = -0.3\n",
     "g.toml: contact.friction: Coulomb's friction coefficient must be in [0, 100], got -0.3"),
    ("friction too large", "[contact]\nlaw = \"coulomb\"\nfriction = 150\n",
     "g.toml: contact.friction: Coulomb's friction coefficient must be in [0, 100], got 150"),
    ("friction with sticking", "[contact]\nlaw = \"sticking\"\nfriction = 0.5\n",
     "g.toml: contact.friction: applies to law = \"coulomb\" only, got 0.5 with law = \"sticking\""),
    ("coulomb without friction", "[contact]\nlaw = \"coulomb\"\n",
     "g.toml: contact.friction: law = \"coulomb\" needs friction = MU, in [0, 100]"),
    ("unknown contact law", "[contact]\nlaw = \"glued\"\n",
     "g.toml: contact.law: must be one of frictionless, sticking, coulomb, got 'glued'"),
    ("unknown contact key", "[contact]\nlaw = \"coulomb\"\nmu = 0.3\n",
     "g.toml: contact.mu: unknown key; allowed: law, friction"),
    ("friction not a number", "[contact]\nlaw = \"coulomb\"\nfriction = \"0.3\"\n",
     "g.toml: contact.friction: Coulomb's friction coefficient must be a number in [0, 100], got '0.3'"),
    ("contact law missing", "[contact]\nfriction = 0.3\n", "g.toml: contact.law: missing"),
    ("contact not a table", "contact = \"coulomb\"\n", "g.toml: contact must be a table with the keys law, friction"),
]:
    case(f"geometry file: {label}", GEO, expected, **{"g.toml": text})
# the command line's --friction alone changes the mu of a coulomb file, and is refused with another law
case("geometry file: friction for a sticking design", GEO + ["--friction", "0.3"],
     "friction: applies to --contact coulomb only, but the geometry file g.toml has law = \"sticking\"",
     **{"g.toml": "[contact]\nlaw = \"sticking\"\n"})
for command in (["example", "--geometry", "{d}/g.toml", "--out", "{d}/out"],
                ["suction", "--geometry", "{d}/g.toml", "--out", "{d}/out/s.json"],
                ["lifetime", "--geometry", "{d}/g.toml", "--out", "{d}/out"]):
    case("geometry file: negative friction", command,
         "g.toml: contact.friction: Coulomb's friction coefficient must be in [0, 100], got -1",
         **{"g.toml": "[contact]\nlaw = \"coulomb\"\nfriction = -1\n"})

# ------------------------------------------------------------------ meshes
MESH = ["stiffness", "--mesh", "{d}/m.msh", "--out", "{d}/out/c.csv"]
LINEAR_MSH = """$MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
4
1 5 9 0
2 6 9 0
3 19 0 0
4 18 0 0
$EndNodes
$Elements
1
1 3 2 1 1 1 2 3 4
$EndElements
"""
case("mesh", MESH, "mesh", **{"m.msh": LINEAR_MSH})
case("mesh", MESH + ["--mesh-unit", "km"], "argument --mesh-unit: invalid choice: 'km'", **{"m.msh": LINEAR_MSH})
case("mesh", ["stiffness", "--mesh", "{d}/m.msh", "--fidelity", "fine", "--out", "{d}/out/c.csv"],
     "mesh: a mesh file fixes the geometry and the mesh; drop --fidelity", **{"m.msh": LINEAR_MSH})

# ------------------------------------------------------------------ sweep files
for label, text, expected in [
    ("unknown key", "[base]\nE_Mpa = 4\n", "base.E_Mpa: unknown key"),
    ("wrong type", "[base]\nF1_N = [\"ten\"]\n", "base.F1_N[0]: expected a finite number"),
    ("bad axis", "[[axes]]\nname = \"angle\"\nvalues = [30]\n", "axes[0].name: expected one of"),
    ("contradictory sampling", "[sampling]\nmethod = \"lhs\"\nn = 4\n[[axes]]\nname = \"nu\"\nvalues = [0.3]\n",
     "axes[0].values: lhs sampling takes low and high, not values"),
    ("bad method", "[sampling]\nmethod = \"random\"\n", "sampling.method: expected one of grid, lhs, sobol"),
    ("bad bounds", "[sampling]\nmethod = \"sobol\"\nn = 4\n[[axes]]\nname = \"nu\"\nlow = 0.4\nhigh = 0.3\n",
     "axes[0].high: must exceed low"),
]:
    case(f"sweep file: {label}", SWEEP, expected, **{"s.toml": text})
# scene files (issue 13) are not on main yet: their cases join this catalogue with them

# the shipped coarse mesh, altered
_SHIPPED_MESH = (Path(__file__).resolve().parents[2] / "meshes" / "cupA_coarse.msh").read_text()
case("mesh", MESH, "mesh: boundary 'cavity' is empty", **{"m.msh": _SHIPPED_MESH.replace('"cavity"', '"lower"')})
case("mesh", MESH + ["--mesh-unit", "m"], "spans 14.2 m with unit 'm'; give the file's length unit",
     **{"m.msh": _SHIPPED_MESH})
# (elements given clockwise are re-oriented when the mesh is read, not refused)

# ------------------------------------------------------------------ scene files
RUN = ["run", "{d}/s.toml", "--out", "{d}/out", "--cache-dir", "{d}/out/cache"]
for label, text, expected in [
    ("unknown table", "[camera]\n[[outputs]]\nkind = \"curve\"\n", "camera: unknown table"),
    ("unknown key", "[cup]\npresett = \"A\"\n[[outputs]]\nkind = \"curve\"\n", "cup.presett: unknown key"),
    ("bad output kind", "[[outputs]]\nkind = \"movie\"\n", "outputs[0].kind: expected one of curve, lifetimes"),
    ("bad figure", "[[outputs]]\nkind = \"figure\"\nfigure = \"pie\"\n", "outputs[0].figure: expected one of"),
    ("negative force", "[loads]\nF1_N = [-3]\n[[outputs]]\nkind = \"lifetimes\"\n", "loads.F1_N[0]: must be > 0"),
    ("contradictory route", "[stiffness]\nsource = \"appendix-a\"\nroute = \"profile\"\n[[outputs]]\nkind = \"lifetimes\"\n",
     "stiffness.route: 'profile' needs source = \"fem\""),
    ("no outputs", "[cup]\npreset = \"A\"\n", "outputs: a scene needs a non-empty list of [[outputs]]"),
    ("unparsable", "[cup\n", "scene: cannot parse"),
    ("missing design file", "[cup]\ngeometry = \"nope.toml\"\n[[outputs]]\nkind = \"curve\"\n", "cup.geometry: no such file"),
]:
    case(f"scene file: {label}", RUN, expected, **{"s.toml": text})
case("scene file: missing", RUN, "scene: no such file")

# ------------------------------------------------------------------ suction tables (valid JSON, wrong types)
import json as _json  # noqa: E402

GOOD_TABLE = {"u_mm": [1, 2], "dp_kPa": [0, 10], "F1_N": [[1, 2], [3, 4]], "V_mm3": [[900, 800], [700, 600]],
              "seal_r_mm": [[10, 10], [11, 11]], "cut_r_mm": [[12, 12], [13, 13]], "E_Pa": 4e6,
              "profiles": [[None, None], [None, None]], "provenance": {"h1_mm": 9.09}}
COUPLED = ["lifetime", "--route", "coupled", "--suction-table", "{d}/t.json", "--out", "{d}/out"]
for label, change, expected in [
    ("not an object", [1, 2, 3], "must hold a JSON object, got a list"),
    ("grid is text", {"V_mm3": "lots"}, "V_mm3: expected a list of numbers, got str"),
    ("ragged grid", {"F1_N": [[1, 2], [3]]}, "F1_N: expected numbers in a regular grid"),
    ("wrong grid shape", {"seal_r_mm": [1, 2]}, "seal_r_mm: expected finite values on the 2 x 2 grid, got shape (2,)"),
    ("modulus is text", {"E_Pa": "4e6"}, "E_Pa: expected a number, got '4e6'"),
    ("modulus is a list", {"E_Pa": [4e6]}, "E_Pa: expected a number"),
    ("u is a number", {"u_mm": 3}, "u_mm: expected a list of numbers, got int"),
    ("profiles not rows", {"profiles": {"a": 1}}, "profiles must be a list of rows"),
    ("profile keys", {"profiles": [[{"r": [1, 2]}, None], [None, None]]}, "profiles[0][0]: expected null or an object"),
    ("profile radii text", {"profiles": [[{"r_mm": "x", "p_kPa": [1, 2]}, None], [None, None]]},
     "profiles[0][0].r_mm: expected a list of numbers"),
    ("profile mismatch", {"profiles": [[{"r_mm": [1, 2, 3], "p_kPa": [1, 2]}, None], [None, None]]},
     "profiles[0][0]: p_Pa: a contact profile needs >= 2 matching"),
    ("provenance text", {"provenance": "fem"}, "provenance must be an object"),
    ("h1 text", {"provenance": {"h1_mm": "9"}}, "provenance must be an object whose h1_mm is a number"),
]:
    table = change if isinstance(change, list) else {**GOOD_TABLE, **change}
    case(f"suction table: {label}", COUPLED, expected, **{"t.json": _json.dumps(table)})
case("suction table: wrong types (example)", ["example", "--route", "coupled", "--suction-table", "{d}/t.json",
                                             "--out", "{d}/out"], "E_Pa: expected a number",
     **{"t.json": _json.dumps({**GOOD_TABLE, "E_Pa": None})})

# ------------------------------------------------------------------ stiffness sidecars (valid JSON, wrong types)
for label, sidecar, expected in [
    ("geometry text", {"provenance": {"geometry": "cup A"}}, "provenance.geometry: expected a table, got str"),
    ("geometry radius text", {"provenance": {"geometry": {"r0_mm": "5", "r1_mm": 19, "alpha_deg": 33, "h1_mm": 9}}},
     "provenance.geometry.r0_mm: expected a number, got '5'"),
    ("contact law a number", {"provenance": {"contact": 3}}, "provenance.contact: expected a string"),
    ("friction text", {"provenance": {"contact": "coulomb", "friction": "0.3"}}, "provenance.friction: expected a number"),
    ("steps a list", {"provenance": {}, "steps": [1, 2]}, "steps: expected a table, got list"),
    ("profile radii a number", {"provenance": {}, "steps": {"pressure_r_mm": 5, "pressure_kPa": 5}},
     "steps.pressure_r_mm: expected one list of numbers per sample"),
    ("profile pressures text", {"provenance": {}, "steps": {"pressure_r_mm": [[1, 2]], "pressure_kPa": [["a", "b"]]}},
     "steps.pressure_kPa: expected one list of numbers per sample"),
    ("profile lengths", {"provenance": {}, "steps": {"pressure_r_mm": [[1, 2]], "pressure_kPa": [[1, 2, 3]]}},
     "steps.pressure_kPa[0]: 3 pressures for 2 radii"),
]:
    case(f"stiffness sidecar: {label}", LIFE + ["--stiffness", "{d}/c.csv"], expected,
         **{"c.csv": GOOD_CURVE, "c.json": _json.dumps(sidecar)})

# ------------------------------------------------------------------ meshes with broken connectivity
_LINES = _SHIPPED_MESH.split("\n")
_AT = _LINES.index("$Elements")


def _mesh_with(edit) -> str:
    lines = list(_LINES)
    edit(lines)
    return "\n".join(lines)


def _out_of_range(lines):
    first = lines[_AT + 2].split()
    lines[_AT + 2] = " ".join(first[:-1] + ["9999"])


def _duplicate(lines):
    lines[_AT + 1] = str(int(lines[_AT + 1]) + 1)
    second = lines[_AT + 3].split()
    lines.insert(lines.index("$EndElements"), " ".join([lines[_AT + 1]] + second[1:]))


def _node_twice(lines):
    first = lines[_AT + 2].split()
    first[-2] = first[-3]
    lines[_AT + 2] = " ".join(first)


case("mesh", MESH, "mesh: cannot read '{d}/m.msh': index 9998 is out of bounds", **{"m.msh": _mesh_with(_out_of_range)})
case("mesh", MESH, "mesh: '{d}/m.msh': element 145 repeats element 2 (the same nodes)", **{"m.msh": _mesh_with(_duplicate)})
case("mesh", MESH, "mesh: '{d}/m.msh': element 1 names one node twice", **{"m.msh": _mesh_with(_node_twice)})

# ------------------------------------------------------------------ output paths (validation.output.check_outputs)
case("output path", ["uc", "--psd", "{d}/p.csv", "--E-MPa", "4", "--p-kPa", "10", "20", "--out", "{d}/p.csv"],
     "--out: '{d}/p.csv' is the input --psd '{d}/p.csv' of this run", **{"p.csv": "q_per_m,C_m4\n" + PSD_ROWS})
case("output path", ["stiffness", "--geometry", "{d}/g.json", "--out", "{d}/g.csv"],
     "--out's sidecar: '{d}/g.json' is the input --geometry '{d}/g.json'", **{"g.json": "r1_mm = 25\n"})
case("output path", LIFE[:1] + ["--uc-table", "{d}/out/u.csv", "--out", "{d}/out"],
     "--out: '{d}/out' holds the input --uc-table", **{"out/u.csv": GOOD_UC, "out/manifest.json": "{}"})
case("output path", LIFE[:1] + ["--out", "{d}/mine"], "holds files cupcheck did not write", **{"mine/notes.txt": "x"})
case("output path", LIFE[:1] + ["--out", ""], "--out: the value is empty")
case("output path", ["uc", "--surface", "pmma-1.89", "--E-MPa", "4", "--p-kPa", "10", "20", "--out="],
     "--out: the value is empty")
case("output path", ["run", "{d}/s.toml", "--out", "{d}/o", "--cache-dir", "{d}/o/cache"],
     "--out: '{d}/o' and --cache-dir '{d}/o/cache' are one output",
     **{"s.toml": "[stiffness]\nsource = \"appendix-a\"\n[[outputs]]\nkind = \"lifetimes\"\n"})
case("output path", ["run", "{d}/o/s.toml", "--out", "{d}/o", "--no-cache"], "--out: '{d}/o' holds the input scene",
     **{"o/s.toml": "[stiffness]\nsource = \"appendix-a\"\n[[outputs]]\nkind = \"lifetimes\"\n", "o/manifest.json": "{}"})
case("output path", ["stiffness", "--out", "{d}/mycup.csv"], "--out's sidecar: '{d}/mycup.json' exists and is not what "
     "cupcheck writes there", **{"mycup.json": '{"r1_mm": 25}'})
# (/dev/null as --out: tests/test_output_paths.py, which also checks that it is left untouched)
case("stiffness CSV: header only", LIFE + ["--stiffness", "{d}/c.csv"],
     "stiffness: '{d}/c.csv' has no rows; a stiffness curve needs at least 2 samples", **{"c.csv": "u_mm,h_mm,F0_N\n"})

# ------------------------------------------------------------------ plausibility at every entry (validation.guards)
# a design file read by the command line: lengths in um named as the slip, before the wall is built
case("design file: thickness table in um", GEO, "g.toml: thickness.r_mm[0] = 5000: did you give um?",
     **{"g.toml": "[thickness]\nr_mm = [5000, 22000]\nd_mm = [2000, 500]\n"})
case("design file: wall thickness in um", GEO, "g.toml: thickness.d_mm[0] = 2000: did you give um?",
     **{"g.toml": "r1_mm = 22\n[thickness]\nr_mm = [5, 22]\nd_mm = [2000, 500]\n"})
# the same guards from a scene file, named by the scene's key path
_CURVE_SCENE = "[cup]\ngeometry = \"g.toml\"\n[stiffness]\nfidelity = \"coarse\"\n[[outputs]]\nkind = \"curve\"\n"
_LIFE_SCENE = "[stiffness]\nsource = \"appendix-a\"\n[[outputs]]\nkind = \"lifetimes\"\n"
for label, design, expected in [
    ("radii in um", "r0_mm = 5000\nr1_mm = 19000\n", "cup.geometry (g.toml): r0_mm = 5000: did you give um?"),
    ("thickness table in um", "[thickness]\nr_mm = [5000, 22000]\nd_mm = [2000, 500]\n",
     "cup.geometry (g.toml): thickness.r_mm[0] = 5000: did you give um?"),
    ("steep cone", "alpha_deg = 85\n", "cup.geometry (g.toml): alpha_deg = 85 is outside 5 .. 80 deg (a tube"),
    ("slender wall", "r1_mm = 50\nalpha_deg = 45\n[thickness]\nr_mm = [5, 50]\nd_mm = [0.1, 0.1]\n",
     "set cup.allow_unusual_design = true"),
]:
    case(f"scene file: design {label}", RUN, expected, **{"s.toml": _CURVE_SCENE, "g.toml": design})
for label, table, expected in [
    ("modulus in GPa", "[material]\nE_MPa = 0.001\n", "material.E_MPa = 0.001: did you give GPa?"),
    ("modulus in Pa", "[material]\nE_MPa = 4e6\n", "material.E_MPa = 4e+06: did you give Pa?"),
    ("tiny force", "[loads]\nF1_N = [1e-300]\n", "loads.F1_N = 1e-300 (plausible: 1e-06 .. 100000 N)"),
    ("force in mN", "[loads]\nF1_N = [5, 1e4, 2e5]\n", "loads.F1_N[2] = 2e+05: did you give mN?"),
    ("unusual flag not a boolean", "[cup]\nallow_unusual_design = \"yes\"\n",
     "cup.allow_unusual_design: expected true or false"),
]:
    case(f"scene file: {label}", RUN, expected, **{"s.toml": table + _LIFE_SCENE})
case("scene file: u_c table in um", RUN, "surface.uc_table: u_c_m at p_over_E = 0.0001 = 2: did you give um",
     **{"s.toml": "[surface]\nuc_table = \"u.csv\"\n" + _LIFE_SCENE,
        "u.csv": "p_over_E,u_c_m\n1e-4,2\n1e-3,1\n1e-2,0.5\n1e-1,0.1\n"})
case("scene file: u_c table unreadable", RUN, "surface.uc_table: p_over_E",
     **{"s.toml": "[surface]\nuc_table = \"u.csv\"\n" + _LIFE_SCENE, "u.csv": "p_over_E,u_c_m\n1e-4,2e-6\n"})
# a stiffness curve against the cup it is used for
_U_CURVE = "u_mm,F0_N\n" + "".join(f"{u},{f}\n" for u, f in ((0, 0), (1, 2.5), (2, 4), (4, 5.5), (8, 14)))
case("stiffness CSV: u in um", LIFE + ["--cup", "A", "--stiffness", "{d}/c.csv"],
     "--stiffness '{d}/c.csv': u_mm runs to 4000 mm, beyond the cup's height h1 = 9.092 mm (the plate stops "
     "at u = h1): did you give um?", **{"c.csv": _U_CURVE.replace("\n8,", "\n4000,").replace("\n4,", "\n3000,")
                                       .replace("\n2,", "\n2000,").replace("\n1,", "\n1000,")})
case("stiffness CSV: modulus against its sidecar", LIFE + ["--cup", "A", "--stiffness", "{d}/c.csv", "--E-MPa", "10"],
     "--E-MPa = 10 MPa, but --stiffness '{d}/c.csv' was computed with E = 4 MPa (its sidecar)",
     **{"c.csv": _U_CURVE, "c.json": _json.dumps({"provenance": {"material": {"E_Pa": 4e6, "nu": 0.49}}})})
case("CLI option", LIFE + ["--force", "1e-300"], "--force = 1e-300 (plausible: 1e-06 .. 100000 N)")

# ------------------------------------------------------------------ sweep semantics and guards
_AXES8 = "".join(f"[[axes]]\nname = \"{name}\"\nvalues = [{', '.join(f'{lo + k * step:g}' for k in range(10))}]\n"
                 for name, lo, step in (("alpha_deg", 20, 2), ("r0_mm", 3, 1), ("r1_mm", 15, 1), ("d0_mm", 1, 0.1),
                                        ("d1_mm", 0.2, 0.04), ("E_MPa", 1, 1), ("nu", 0.3, 0.02),
                                        ("r_start_mm", 10, 0.4)))
for label, text, expected in [
    ("duplicate axis value", "[[axes]]\nname = \"alpha_deg\"\nvalues = [30, 33, 30]\n",
     "axes[0].values[2]: 30.0 appears twice on the axis alpha_deg"),
    ("duplicate surface value", "[[axes]]\nname = \"surface\"\nvalues = [\"pmma-1.89\", \"pmma-1.89\"]\n",
     "axes[0].values[1]: 'pmma-1.89' appears twice"),
    ("duplicate force", "[base]\nF1_N = [10, 10.0]\n", "base.F1_N: 10 appears twice"),
    ("empty force list", "[base]\nF1_N = []\n", "base.F1_N: expected at least one value"),
    ("unknown base surface", "[base]\nsurface = \"glass\"\n", "base.surface: unknown surface preset 'glass'"),
    ("unknown surface on an axis", "[[axes]]\nname = \"surface\"\nvalues = [\"pmma-1.89\", \"glass\"]\n",
     "axes[0].values[1]: unknown surface preset 'glass'"),
    ("grid too large", _AXES8, "axes: the grid has 10 x 10 x 10 x 10 x 10 x 10 x 10 x 10 = 1e+08 designs"),
    ("radius in um on an axis", "[[axes]]\nname = \"r1_mm\"\nvalues = [19, 19000]\n",
     "axes[0].values[1] = 1.9e+04: did you give um?"),
    ("thickness in um", "[base]\nd0_mm = 2500\n", "base.d0_mm = 2500: did you give um?"),
    ("modulus in Pa", "[base]\nE_MPa = 4e6\n", "base.E_MPa = 4e+06: did you give Pa?"),
    ("modulus bound in Pa", "[sampling]\nmethod = \"lhs\"\nn = 4\n[[axes]]\nname = \"E_MPa\"\nlow = 1\nhigh = 4e6\n",
     "axes[0].high = 4e+06: did you give Pa?"),
    ("tiny force", "[base]\nF1_N = [1e-12]\n", "base.F1_N = 1e-12 (plausible"),
]:
    case(f"sweep file: {label}", SWEEP, expected, **{"s.toml": text})
case("sweep file: its scene's modulus", SWEEP, "material.E_MPa = 0.001: did you give GPa?",
     **{"s.toml": "scene = \"b.toml\"\n", "b.toml": "[material]\nE_MPa = 0.001\n[[outputs]]\nkind = \"lifetimes\"\n"})
# the start radius, named as written (it was r_start_m, in metres, after the work had started)
case("scene file: start radius outside the wall", RUN, "loads.r_start_mm = 3 (the start radius must lie in (r0, r1) = (5, 19) mm)",
     **{"s.toml": "[loads]\nr_start_mm = 3\n" + _LIFE_SCENE})
case("scene file: start radius in um", RUN, "loads.r_start_mm = 1.2e+04: did you give um?",
     **{"s.toml": "[loads]\nr_start_mm = 12000\n" + _LIFE_SCENE})
case("scene file: swept start radius in m", RUN, "sweep.values[1] = 0.012: did you give m?",
     **{"s.toml": "[sweep]\nkey = \"loads.r_start_mm\"\nvalues = [10, 0.012]\n" + _LIFE_SCENE})
case("sweep file: start radius outside the wall", SWEEP, "base.r_start_mm = 3 (the start radius must lie in (r0, r1)",
     **{"s.toml": "[base]\nr_start_mm = 3\n"})
case("sweep file: start radius on an axis", SWEEP, "axes[0].values[2] = 30 (the start radius must lie in",
     **{"s.toml": "[[axes]]\nname = \"r_start_mm\"\nvalues = [10, 12, 30]\n"})
for command in (["lifetime", "--geometry", "{d}/g.toml", "--out", "{d}/out"],
                ["example", "--geometry", "{d}/g.toml", "--out", "{d}/out"],
                ["suction", "--geometry", "{d}/g.toml", "--out", "{d}/out/s.json"]):
    case("design file: thickness table in um", command, "g.toml: thickness.r_mm[0] = 5000: did you give um?",
         **{"g.toml": "[thickness]\nr_mm = [5000, 22000]\nd_mm = [2000, 500]\n"})
