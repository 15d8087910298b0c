"""sweep.materials.prony_files: Prony tables read from every accepted format (issue 36 item 1).

The reference table is tests/data/prony/pdms_fit_dma.json, the output of ``sweep fit-dma
--maxwell 18 --json`` on the PDMS MPL's DMA data (tests/data/prony/make_tables.py); the other
files of tests/data/prony hold the same table in pyvisco's, ANSYS's and this project's format.
The reference numbers are taken from the JSON with :mod:`json` here, not through the reader.

Tolerances: the formats hold the same numbers up to the products a format's definition needs
(pyvisco's E_i = E_0 alpha_i, the MPa scale, ANSYS's a_i = E_i/EX), a few units of 1e-16;
the relaxed modulus of a relative table is E_0 (1 - sum alpha), which loses log10(1/k) ~ 2.7
digits to cancellation (k = E0/Einf = 2.2e-3 here). Hence 1e-12 relative.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from sweep.errors import InputError
from sweep.materials import SLS, MPLRetardation, PronyTable, read_prony

DATA = Path(__file__).resolve().parents[1] / "data" / "prony"
FILES = {"pyvisco": "pdms_prony.csv", "ansys": "pdms_prony_ansys.mpl",
         "visco-sweep": "pdms_prony_visco_sweep.csv", "fit-dma": "pdms_fit_dma.json"}
RTOL = 1e-12


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b) / np.abs(b)))


def reference():
    """E0 [Pa], the non-zero arm moduli [Pa] and times [s] (ascending) of the JSON fit."""
    mx = json.loads((DATA / FILES["fit-dma"]).read_text())["maxwell"]
    E = np.array(mx["moduli"], float)
    tau = np.array(mx["times"], float)
    keep = E > 0
    order = np.argsort(tau[keep])
    return float(mx["E0"]), E[keep][order], tau[keep][order]


# ================================================================ one table, every format

@pytest.mark.parametrize("fmt", sorted(FILES))
def test_every_format_gives_the_same_table(fmt):
    E0, E, tau = reference()
    t = read_prony(DATA / FILES[fmt])
    assert t.source_format == fmt
    assert t.name == Path(FILES[fmt]).stem
    assert t.form == "wiechert" and (t.modulus_unit, t.time_unit) == ("Pa", "s")
    assert t.n_arms == E.size == 15          # 18 arms, three of them 0 (NNLS), dropped
    assert rel(t.times, tau) < RTOL
    assert rel(t.weights, E) < RTOL
    assert rel(t.E0, E0) < RTOL
    assert rel(t.Einf, E0 + E.sum()) < RTOL
    m = t.material
    assert rel(m.maxwell_moduli, E) < RTOL and rel(m.maxwell_times, tau) < RTOL
    assert rel([m.E0, m.Einf], [E0, E0 + E.sum()]) < RTOL


def test_every_format_hashes_the_same():
    hashes = {fmt: read_prony(DATA / f).content_hash() for fmt, f in FILES.items()}
    assert len(set(hashes.values())) == 1, hashes
    assert len(hashes["pyvisco"]) == 16 and int(hashes["pyvisco"], 16) >= 0


def test_hash_follows_the_numbers_not_the_path(tmp_path):
    E0, E, tau = reference()
    base = read_prony({"tau": tau.tolist(), "E": E.tolist(), "E0": E0})
    copy = tmp_path / "elsewhere.csv"
    copy.write_text((DATA / FILES["visco-sweep"]).read_text())
    assert read_prony(copy).content_hash() == base.content_hash()
    # a table in another order is the same table
    back = read_prony({"tau": tau[::-1].tolist(), "E": E[::-1].tolist(), "E0": E0})
    assert back.content_hash() == base.content_hash()
    for changed in (
        {"tau": tau.tolist(), "E": (E * np.where(np.arange(E.size) == 3, 1 + 1e-6, 1)).tolist(),
         "E0": E0},                                                 # one arm by 1e-6
        {"tau": tau.tolist(), "E": E.tolist(), "E0": E0 * (1 + 1e-6)},   # the relaxed modulus
        {"tau": (tau * np.where(np.arange(E.size) == 0, 2.0, 1)).tolist(), "E": E.tolist(),
         "E0": E0},                                                 # one time
        {"tau": tau[:-1].tolist(), "E": E[:-1].tolist(), "E0": E0},  # one arm fewer
    ):
        assert read_prony(changed).content_hash() != base.content_hash()


def test_ansys_card_as_ansys_writes_it(tmp_path):
    """Abbreviated labels, a TBFIELD temperature, blank STLOC continuing, comments."""
    E0, E, tau = reference()
    Einf = E0 + E.sum()
    consts = np.column_stack([E / Einf, tau]).ravel().tolist()
    lines = ["/COM,ANSYS RELEASE 2020 R1", "/NOP", "TBDEL,ALL,_MATL",
             f"TB,PRON,_MATL   ,   1,  {E.size},SHEA", "TBFIELD,Temps,0.000000"]
    lines += [f"TBDATA,{s + 1}," + ",".join(f"{c!r}" for c in consts[s:s + 3])
              for s in range(0, 6, 3)]
    lines += ["TBDATA,," + ",".join(f"{c!r}" for c in consts[s:s + 2]) + ",  ! two a line"
              for s in range(6, len(consts), 2)]
    lines += ["TBIN,NORM,1", "/GO"]
    card = tmp_path / "prony_terms.MPL"
    card.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="no instantaneous modulus"):
        read_prony(card)
    t = read_prony({"prony": str(card), "Einf": Einf})
    assert t.modulus_unit is None                     # no /UNITS: the numbers as given
    assert rel(t.weights, E) < RTOL and rel(t.times, tau) < RTOL and rel(t.E0, E0) < RTOL
    assert t.content_hash() == read_prony(DATA / FILES["fit-dma"]).content_hash()


def test_abaqus_deck_gives_the_same_table():
    """tests/data/prony/pdms_prony_abaqus.inp: ``*ELASTIC, MODULI=INSTANTANEOUS`` (E = Einf)
    and ``*VISCOELASTIC, TIME=PRONY`` rows g_i = E_i/Einf, k_i = 0, tau_i; Abaqus states no
    units, so the numbers are as given (here Pa and s)."""
    E0, E, tau = reference()
    t = read_prony(DATA / "pdms_prony_abaqus.inp")
    assert t.source_format == "abaqus" and t.name == "pdms_prony_abaqus"
    assert t.modulus_unit is None and t.form == "wiechert" and t.n_arms == E.size
    assert rel(t.weights, E) < RTOL and rel(t.times, tau) < RTOL and rel(t.E0, E0) < RTOL
    assert t.content_hash() == read_prony(DATA / FILES["fit-dma"]).content_hash()


def _abaqus(E0, E, tau, *, elastic, k="0."):
    Einf = float(E0 + E.sum())
    rows = [f"{e / Einf!r}, {k if k != 'g' else repr(e / Einf)}, {t!r},"
            for e, t in zip(E.tolist(), tau.tolist())]
    return "\n".join(["** a deck as a user writes it: lower case, comments, trailing commas",
                      "*Heading", "pdms", "*material, name=pdms", "*DENSITY", "965.",
                      *elastic, "*viscoelastic , time = prony", *rows, "*Trs, definition=WLF",
                      "20., 8.86, 101.6", "*Step", "*End step"]) + "\n"


def test_abaqus_deck_long_term_modulus_and_bulk_ratios(tmp_path):
    """The default MODULI=LONG TERM gives the relaxed modulus (E_inst = E (1 - sum g_i)^-1;
    the relaxed modulus of the relative rows loses ~2.7 digits, k = 2.2e-3: 1e-12 holds);
    k_i = g_i is read as k_i = 0 (a constant nu); no *ELASTIC needs Einf given."""
    E0, E, tau = reference()
    ref = read_prony(DATA / FILES["fit-dma"])
    long_term = _write(tmp_path, "lt.inp", _abaqus(E0, E, tau, elastic=["*Elastic",
                                                                         f"{float(E0)!r}, 0.49"],
                                                 k="g"))
    t = read_prony(long_term)
    assert rel(t.weights, E) < RTOL and rel(t.E0, E0) < RTOL and rel(t.Einf, ref.Einf) < RTOL
    assert t.content_hash() == ref.content_hash()
    bare = _write(tmp_path, "bare.inp", _abaqus(E0, E, tau, elastic=[]))
    with pytest.raises(InputError, match="no modulus .*give Einf"):
        read_prony(bare)
    t = read_prony({"prony": str(bare), "Einf": ref.Einf})
    assert rel(t.weights, E) < RTOL and t.content_hash() == ref.content_hash()


def test_pyvisco_shear_table_needs_nu(tmp_path):
    E0, E, tau = reference()
    Einf = float(E0 + E.sum())
    nu = 0.5
    G_0 = Einf / (2 * (1 + nu)) / 1e3                 # kPa
    rows = ["i,tau_i,alpha_i,G_0,G_i", "-,s,-,kPa,kPa"]
    rows += [f"{i + 1},{t!r},{e / Einf!r},{G_0!r},{G_0 * e / Einf!r}"
             for i, (t, e) in enumerate(zip(tau.tolist(), E.tolist()))]
    f = tmp_path / "df_prony.csv"
    f.write_text("\n".join(rows) + "\n")
    with pytest.raises(InputError, match="shear table .* needs Poisson's ratio nu"):
        read_prony(f)
    t = read_prony(f, nu=nu)
    assert rel(t.weights, E) < RTOL and rel(t.Einf, Einf) < RTOL and rel(t.E0, E0) < RTOL
    assert t.content_hash() == read_prony(DATA / FILES["pyvisco"]).content_hash()


def test_paths_names_and_specs(tmp_path):
    t = read_prony({"prony": FILES["pyvisco"], "name": "PDMS 18 arms"}, base_dir=DATA)
    assert t.name == "PDMS 18 arms" and t.source == str(DATA / FILES["pyvisco"])
    assert read_prony(t) is t
    assert isinstance(t, PronyTable) and "PDMS 18 arms (pyvisco, wiechert, 15 arms" in t.summary()
    # to_csv writes this project's CSV, read back to the same table
    back = read_prony(t.to_csv(tmp_path / "t.csv"))
    assert back.source_format == "visco-sweep" and back.content_hash() == t.content_hash()
    assert rel(back.weights, t.weights) == 0.0 and rel(back.E0, t.E0) == 0.0
    # a JSON file holding an inline table
    js = tmp_path / "inline.json"
    js.write_text(json.dumps({"tau": t.times.tolist(), "E": t.weights.tolist(), "E0": t.E0}))
    assert read_prony(js).content_hash() == t.content_hash()


# ================================================================ bad tables

def _write(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text)
    return p


PV_HEAD = "i,tau_i,alpha_i,E_0,E_i\n-,s,-,MPa,MPa\n"
VS_HEAD = "# visco-sweep prony\n# E0 = 1e6\ntau,E\n"
ANSYS = "MP,EX,1,1e9\nTB,PRONY,1,1,2,SHEAR\nTBDATA,1,{}\n"

BAD = [
    # (id, file name or None for inline, content, message fragment)
    ("negative time", None, {"tau": [1.0, -1e-3], "E": [1e6, 2e6], "E0": 1e6},
     r"times tau must be > 0 \(got tau\[1\] = -0.001\)"),
    ("zero time", "t.csv", VS_HEAD + "0,1e6\n", "times tau must be > 0"),
    ("negative modulus", None, {"tau": [1.0, 2.0], "E": [1e6, -2e6], "E0": 1e6},
     r"moduli E must be >= 0, so that the relaxation modulus never increases \(got E\[1\]"),
    ("negative Kelvin weight", None, {"tau": [1.0], "c": [-0.1], "E0": 1e6},
     "weights c must be >= 0"),
    ("negative alpha", "p.csv", PV_HEAD + "1,1.0,-0.1,10.0,-1.0\n",
     r"relative moduli alpha_i must be >= 0"),
    ("alpha sum 1", "p.csv", PV_HEAD + "1,1.0,0.5,10.0,5.0\n2,2.0,0.5,10.0,5.0\n",
     r"relative moduli alpha_i must sum to < 1 .*got sum 1\)"),
    ("ANSYS a_i sum > 1", "c.mac", ANSYS.format("0.7,1.0,0.6,2.0"),
     r"relative moduli a_i must sum to < 1"),
    ("Kelvin sum 1", None, {"tau": [1.0, 2.0], "c": [0.5, 0.5], "E0": 1e6},
     r"Kelvin weights c must sum to < 1"),
    ("Einf below the arms", None, {"tau": [1.0], "E": [2e6], "Einf": 1e6},
     r"Einf = 1e\+06 must exceed the sum of the arm moduli"),
    ("lengths", None, {"tau": [1.0, 2.0], "E": [1e6], "E0": 1e6},
     r"tau and E must have the same length \(got 2 and 1\)"),
    ("ANSYS odd constants", "c.mac", ANSYS.format("0.1,1.0,0.2"), "an odd number"),
    ("ANSYS NPTS", "c.mac", ANSYS.format("0.1,1.0,0.2,2.0,0.1,3.0"),
     r"NPTS = 2 but TBDATA gives 3 pairs"),
    ("non-numeric CSV cell", "t.csv", VS_HEAD + "1.0,1e6\n2.0,abc\n",
     r"t.csv line 5, column E: must be a number \(got 'abc'\)"),
    ("non-numeric pyvisco cell", "p.csv", PV_HEAD + "1,1.0,0.1,10.0,1.0\n2,x,0.1,10.0,1.0\n",
     r"p.csv line 4, column tau_i: must be a number"),
    ("non-numeric inline", None, {"tau": [1.0, "fast"], "E": [1e6, 1e6], "E0": 1e6},
     r"prony tau\[1\]: must be a number"),
    ("non-finite", None, {"tau": [1.0], "E": [float("nan")], "E0": 1e6}, "finite number"),
    ("empty CSV table", "t.csv", VS_HEAD, "empty table"),
    ("empty pyvisco table", "p.csv", PV_HEAD, "empty table"),
    ("empty inline table", None, {"tau": [], "E": [], "E0": 1e6}, "empty table"),
    ("empty ANSYS table", "c.mac", "MP,EX,1,1e9\nTB,PRONY,1,1,2,SHEAR\n", "empty Prony table"),
    ("E_i against alpha_i", "p.csv", PV_HEAD + "1,1.0,0.1,10.0,2.0\n",
     r"E_i must equal E_0 x alpha_i"),
    ("bulk only", "c.mac", "MP,EX,1,1e9\nTB,PRONY,1,1,1,BULK\nTBDATA,1,0.1,1.0\n",
     "no TB,PRONY,...,SHEAR table"),
    ("bulk differs", "c.mac", ANSYS.format("0.1,1.0,0.2,2.0")
     + "TB,PRONY,1,1,2,BULK\nTBDATA,1,0.3,1.0,0.2,2.0\n", "BULK Prony table differs"),
    ("Abaqus frequency domain", "a.inp", "*Elastic\n1e6, 0.5\n*Viscoelastic, frequency=PRONY\n"
     "0.5, 0., 1.\n", "needs TIME=PRONY, the Prony series itself \\(got FREQUENCY=PRONY\\)"),
    ("Abaqus bulk ratios", "a.inp", "*Elastic\n1e6, 0.4\n*Viscoelastic, time=PRONY\n"
     "0.5, 0.5, 1.\n0.2, 0.1, 10.\n", r"a.inp line 5: the bulk ratio k_i = 0.1 differs from "
     r"the shear ratio g_i = 0.2"),
    ("Abaqus short row", "a.inp", "*Elastic\n1e6, 0.5\n*Viscoelastic, time=PRONY\n0.5, 1.\n",
     r"line 4: needs 3 values g_i, k_i, tau_i \(got 2\)"),
    ("Abaqus temperatures", "a.inp", "*Elastic\n1e6, 0.5, 20.\n2e6, 0.5, 40.\n"
     "*Viscoelastic, time=PRONY\n0.5, 0., 1.\n", "temperature-dependent moduli"),
    ("Abaqus two materials", "a.inp", "*Elastic\n1e6, 0.5\n*Viscoelastic, time=PRONY\n"
     "0.5, 0., 1.\n*Viscoelastic, time=PRONY\n0.5, 0., 1.\n",
     r"the deck has 2 \*VISCOELASTIC blocks \(lines 3, 5\)"),
    ("Abaqus empty", "a.inp", "*Elastic\n1e6, 0.5\n*Viscoelastic, time=PRONY\n",
     "empty Prony table"),
    ("Abaqus g sum 1, instantaneous", "a.inp", "*Elastic, moduli=instantaneous\n1e6, 0.5\n"
     "*Viscoelastic, time=PRONY\n0.6, 0., 1.\n0.4, 0., 2.\n",
     "relative moduli g_i must sum to < 1"),
    ("Abaqus g sum 1, long term", "a.inp", "*Elastic\n1e6, 0.5\n*Viscoelastic, time=PRONY\n"
     "0.6, 0., 1.\n0.4, 0., 2.\n", "relative moduli g_i must sum to < 1"),
    ("Abaqus negative g", "a.inp", "*Elastic\n1e6, 0.5\n*Viscoelastic, time=PRONY\n"
     "-0.1, 0., 1.\n", "relative moduli g_i must be >= 0"),
    ("Abaqus non-numeric", "a.inp", "*Elastic\n1e6, 0.5\n*Viscoelastic, time=PRONY\n"
     "0.1, 0., fast\n", r"line 4, tau_i: must be a number \(got 'fast'\)"),
    # pyvisco normalizes an overshooting fit's alpha_i to sum 1: in floating point 1 - 1e-16,
    # a relaxed modulus of rounding (the BEM then raised, the crack-front model gave 23376)
    ("relative moduli summing to 1 within rounding", "p.csv", PV_HEAD
     + "1,0.0001,0.24694527138251782,1500.0,370.41790707377675\n"
       "2,0.001,0.2478465005495941,1500.0,371.7697508243911\n"
       "3,0.01,0.1580829171772686,1500.0,237.1243757659029\n"
       "4,0.1,0.0876733453823922,1500.0,131.5100180735883\n"
       "5,1.0,0.016543954739349945,1500.0,24.815932109024917\n"
       "6,10.0,0.11760346392870505,1500.0,176.40519589305757\n"
       "7,100.0,0.12530454684017214,1500.0,187.9568202602582\n",
     r"the arms sum to the instantaneous modulus within rounding \(the relaxed modulus, their "
     r"difference, is 1.6e-16 Einf, below 1e-12 Einf\): a liquid"),
    ("a unit beside a value", "t.csv", "# visco-sweep prony\n# E0 = 1.5 MPa\ntau,E\n1,1\n",
     r"t.csv line 2: E0 must be one value \(got '1.5 MPa'; a modulus's unit goes on its own "
     r"line"),
    ("Einf beside a table that gives it", "p.csv", PV_HEAD + "1,1.0,0.1,10.0,1.0\n",
     r"Einf is given with a table only for an ANSYS card without MP,EX or an Abaqus deck "
     r"without \*ELASTIC; this pyvisco table gives its moduli itself \(got Einf = 5e\+09\)"),
    ("no format", "notes.txt", "omega,E'\n1,2\n", "not a Prony table in any accepted format"),
    ("binary", "x.xls", None, "not a Prony table"),
    ("MPL-only fit", "fit.json", json.dumps({"mpl": {"E0": 1.4e6, "Einf": 3e9, "n": 0.22,
                                                     "tau0": 0.019}, "maxwell": None}),
     r"holds only an MPL fit \(E0 = 1.4e\+06, Einf = 3e\+09, n = 0.22, tau0 = 0.019\)"),
    ("liquid fit", "fit.json", json.dumps({"mpl": {}, "maxwell": {"E0": 0.0, "moduli": [1.0],
                                                                  "times": [1.0]}}),
     "E0 .* must be > 0"),
    ("unknown key", None, {"tau": [1.0], "E": [1e6], "E0": 1e6, "units": "Pa"},
     r"unknown key 'units' \(allowed: tau, E, c"),
    ("both plateaus", None, {"tau": [1.0], "E": [1e6], "E0": 1e6, "Einf": 3e6},
     "exactly one of E0 .* or Einf"),
    ("bad unit", "t.csv", "# visco-sweep prony\n# E0 = 1\n# modulus_unit = psi\n"
     "# time_unit = s\ntau,E\n1,1\n", "modulus unit must be one of Pa, kPa, MPa, GPa"),
    ("bad form", None, {"tau": [1.0], "E": [1e6], "E0": 1e6, "form": "kelvin"},
     "form kelvin needs the column c"),
    ("recorded moduli that disagree", None,
     {"tau": [1.0], "E": [9e6], "E0": 1e6, "Einf": 1.1e7, "recorded": True},
     "E0 = 1e.06 and Einf = 1.1e.07 disagree"),
    ("every weight zero", None, {"tau": [1.0, 2.0], "c": [0.0, 0.0], "E0": 1, "form": "kelvin"},
     "every one of the weights c is 0"),
    ("every modulus zero", None, {"tau": [1.0], "E": [0.0], "E0": 1e6},
     "every one of the moduli E is 0"),
]


@pytest.mark.parametrize("case", BAD, ids=[c[0] for c in BAD])
def test_bad_tables_give_one_line_naming_the_problem(tmp_path, case):
    _, name, content, fragment = case
    if name is None:
        spec = content
    elif content is None:
        spec = tmp_path / name
        spec.write_bytes(b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1\x00\xff\xfe")
    else:
        spec = _write(tmp_path, name, content)
    with pytest.raises(InputError, match=fragment) as err:
        read_prony(spec, nu=0.5, Einf=5e9 if case[0].startswith("Einf beside") else None)
    msg = str(err.value)
    assert "\n" not in msg
    assert (str(spec) in msg) if name is not None else msg.startswith("prony")


def test_what_a_lab_file_carries_besides_the_table(tmp_path):
    """A UTF-8 BOM (Excel's "CSV UTF-8") in every text format, a comment holding "=" in this
    project's CSV, CRLF line ends: read as the table (the BOM had made each "not a Prony
    table in any accepted format", the comment "unknown key")."""
    ref = read_prony(DATA / FILES["visco-sweep"])
    for name in FILES.values():
        text = (DATA / name).read_text()
        p = tmp_path / f"bom_{name}"
        p.write_text("\ufeff" + text.replace("\n", "\r\n"), encoding="utf-8", newline="")
        assert read_prony(p).content_hash() == ref.content_hash(), name
    text = (DATA / FILES["visco-sweep"]).read_text().replace(
        "# form", "# DMA master curve at T_ref = 20 C, shifted\n# form")
    assert read_prony(_write(tmp_path, "c.csv", text)).content_hash() == ref.content_hash()
    with pytest.raises(InputError, match=r"unknown key 'E_0' \(allowed: form, E0"):
        read_prony(_write(tmp_path, "k.csv", text.replace("# E0", "# E_0")))


def test_an_ansys_card_stating_its_units_takes_einf_in_pa(tmp_path):
    """/UNITS,MPA: the card's numbers are MPa; an Einf given beside it is the table's
    modulus as read, in Pa (it had been scaled by 1e6 again: 3e15 Pa); MP,EX in the card
    and an Einf that differs are refused, in Pa."""
    card = _write(tmp_path, "c.mpl", "/UNITS,MPA\nTB,PRONY,1,1,2,SHEAR\nTBDATA,1,0.5,0.001,0.3,0.1\n")
    t = read_prony({"prony": str(card), "Einf": 3.0e9})
    assert (t.Einf, t.modulus_unit) == (3.0e9, "Pa") and rel(t.E0, 0.2 * 3.0e9) < RTOL
    with_ex = _write(tmp_path, "e.mpl", "/UNITS,MPA\nMP,EX,1,3000\n" + card.read_text())
    assert read_prony(with_ex).Einf == 3.0e9
    assert read_prony({"prony": str(with_ex), "Einf": 3.0e9}).Einf == 3.0e9
    with pytest.raises(InputError, match=r"Einf = 3000 given with the card differs from its "
                                         r"MP,EX = 3e\+09 Pa; give one"):
        read_prony({"prony": str(with_ex), "Einf": 3000})


def test_missing_file_and_bad_arguments(tmp_path):
    with pytest.raises(InputError, match=r"missing.csv: cannot read the Prony table"):
        read_prony(tmp_path / "missing.csv")
    with pytest.raises(InputError, match=r"nu must be in \(-1, 0.5\]"):
        read_prony(DATA / FILES["pyvisco"], nu=0.7)
    with pytest.raises(InputError, match="prony must be a file path or a table"):
        read_prony(3.0)


# ================================================================ the material it defines

def test_relaxation_modulus_is_the_prony_closed_form():
    E0, E, tau = reference()
    t = np.concatenate([[0.0], np.logspace(-16, 4, 201)])
    closed = E0 + (E[None, :] * np.exp(-t[:, None] / tau[None, :])).sum(axis=1)
    for f in FILES.values():
        m = read_prony(DATA / f).material
        assert rel(m.relaxation_modulus(t), closed) < RTOL
    # R(0) = Einf, R(inf) = E0, never increasing
    assert closed[0] == pytest.approx(E0 + E.sum(), rel=1e-15)
    assert np.all(np.diff(closed) <= 0)


def test_sls_as_a_one_term_table_is_the_sls():
    E0, Einf, tau0 = 1.2e6, 4.8e8, 0.35            # k = 1/400
    sls = SLS(E0, Einf, tau0)
    k = E0 / Einf
    t = np.concatenate([[0.0], np.logspace(-6, 4, 121)]) * tau0
    wiechert = read_prony({"tau": [k * tau0], "E": [Einf - E0], "E0": E0})
    kelvin = read_prony({"tau": [tau0], "c": [1 - k], "Einf": Einf, "form": "kelvin"})
    for tab in (wiechert, kelvin):
        assert rel(tab.material.creep_compliance(t), sls.creep_compliance(t)) < RTOL
        assert rel(tab.material.relaxation_modulus(t), sls.relaxation_modulus(t)) < RTOL
        assert rel([tab.E0, tab.Einf], [E0, Einf]) < RTOL


def test_mpl_prony_series_as_a_table_reproduces_the_mpl(tmp_path):
    """The paper's PDMS MPL: its own Prony (Kelvin) series on [1e-6, 1e4] tau0 at rtol 1e-4,
    written as this project's CSV and read back, reproduces the MPL's creep compliance
    within that rtol on the window. The series' lumped slow term (time inf: modes slower than
    the window, a constant there) is written with the finite time 1e6 t_max: inside the
    window exp(-t/(1e6 t_max)) differs from 1 by <= 1e-6, i.e. a relative change of Chat of
    at most c_inf 1e-6 / Chat(t_min), under 1e-9 here (c_inf ~ 1e-5, Chat >= 0.04)."""
    mpl = MPLRetardation(1.458e6, 3.089e9, 0.2207, 0.01876)
    t_min, t_max, rtol = 1e-6, 1e4, 1e-4
    series = mpl.prony(t_min, t_max, rtol=rtol)
    assert series.converged
    times = np.where(np.isinf(series.times), 1e6 * t_max, series.times) * mpl.tau0
    lines = ["# visco-sweep prony", "# form = kelvin", f"# E0 = {mpl.E0!r}",
             "# modulus_unit = Pa", "# time_unit = s", "tau,c"]
    lines += [f"{t!r},{c!r}" for t, c in zip(times.tolist(), series.weights.tolist())]
    f = _write(tmp_path, "mpl_series.csv", "\n".join(lines) + "\n")
    tab = read_prony(f)
    assert tab.form == "kelvin" and tab.n_arms == series.n_terms
    t = np.logspace(math.log10(t_min), math.log10(t_max), 2001) * mpl.tau0
    err = rel(tab.material.creep_compliance(t), mpl.creep_compliance(t))
    assert err <= rtol
    # and the table is the series: the same Chat to rounding
    assert rel(tab.material.normalized_creep_compliance(t),
               series(np.minimum(t / mpl.tau0, 1e300))) < 1e-9
