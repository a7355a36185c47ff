"""sw/mstrack_drv.c: compiled with gcc -Wall -Wextra -Werror -std=c99; its decode == the Python decoder.

A host test program (sw/test/mstrack_drv_test.c) is fed result words produced by the fixed-point
model (synthetic scene; real frames and `mstrack vectors` records when ../shared/data is there) and
random words, and register values as ms_tracker_axi presents them (encoded with the register map
read from regs/ms_tracker_regs.rdl); every field it prints is compared with
:func:`mstrack.fixed.unpack_result` / :func:`~mstrack.fixed.unpack_result_v2`.
"""
from __future__ import annotations

import os
import random
import shutil
import subprocess
from pathlib import Path

import pytest

from mstrack.hw.cosim import COMPARED_FIELDS, expected_results
from mstrack.fixed import (FixedParams, core_generics, pack_result, result_layout, result_layout_v2,
                           unpack_result, unpack_result_v2)
from mstrack.track.params import TrackerParams
from mstrack.hw.regs import REPO, register_map

SW = REPO / "sw"
CFLAGS = ["-Wall", "-Wextra", "-Werror", "-std=c99"]
SEQ = REPO.parent / "shared" / "data" / "sequences" / "Girl"


def _gcc() -> str:
    gcc = shutil.which("gcc")
    if gcc is None:
        if os.environ.get("MSTRACK_REQUIRE_TOOLS", "") not in ("", "0"):
            pytest.fail("gcc not found (apt-get install gcc) and MSTRACK_REQUIRE_TOOLS is set")
        pytest.skip("gcc not found")
    return gcc


@pytest.fixture(scope="module")
def drv(tmp_path_factory) -> Path:
    """The host test program, built with the driver."""
    gcc = _gcc()
    out = tmp_path_factory.mktemp("drv") / "mstrack_drv_test"
    subprocess.run([gcc, *CFLAGS, f"-I{SW}", str(SW / "mstrack_drv.c"), str(SW / "test" / "mstrack_drv_test.c"),
                    "-o", str(out)], check=True, capture_output=True, text=True)
    return out


@pytest.mark.parametrize("io", ["volatile", "extern"])
def test_driver_compiles_alone(tmp_path, io):
    """The driver and the generated headers, compiled as firmware would (object only): register
    accesses as volatile loads / stores, or (``-DMSTRACK_IO_EXTERN``) through the platform's
    mstrack_io_read32 / mstrack_io_write32, then its only undefined symbols (none with volatile accesses)."""
    gcc = _gcc()
    extra = ["-DMSTRACK_IO_EXTERN"] if io == "extern" else []
    r = subprocess.run([gcc, *CFLAGS, "-pedantic", *extra, f"-I{SW}", "-c", str(SW / "mstrack_drv.c"), "-o",
                        str(tmp_path / "drv.o")], capture_output=True, text=True)
    # -pedantic: the generated header's __attribute__((packed)) struct is the one GNU extension
    assert r.returncode == 0 or "attribute" in r.stderr, r.stderr
    nm = shutil.which("nm")
    if nm and r.returncode == 0:
        undef = subprocess.run([nm, "-u", str(tmp_path / "drv.o")], capture_output=True, text=True).stdout.split()
        want = {"mstrack_io_read32", "mstrack_io_write32"} if io == "extern" else set()
        assert {u for u in undef if u != "U"} == want


def _run(drv: Path, lines: list[str]) -> list[dict[str, int]]:
    r = subprocess.run([str(drv)], input="\n".join(lines) + "\n", capture_output=True, text=True, check=True)
    out = []
    for line in r.stdout.splitlines():
        out.append({k: int(v) for k, v in (t.split("=") for t in line.split() if "=" in t)})
    assert len(out) == len(lines), r.stdout
    return out


def _words(word: int) -> str:
    return " ".join(f"{(word >> (32 * i)) & 0xFFFFFFFF:x}" for i in range(5))


def model_words() -> list[int]:
    """Result words of the fixed-point model: a synthetic scene, real frames and vectors records."""
    from mstrack.io.synthetic import make_scene
    tp, fp = TrackerParams(), FixedParams()
    frames, _ = make_scene(6, 96, 72, seed=1)
    res = expected_results(frames, (36, 24, 20, 18), tp, fp)
    if SEQ.is_dir():
        import cv2
        files = sorted((SEQ / "img").glob("*.jpg"))[:6]
        from mstrack.io.data import load_sequence
        from mstrack.fixed.blocks import round_box
        box = round_box(*[float(v) for v in load_sequence(SEQ).gt[0]])
        res += expected_results([cv2.imread(str(f)) for f in files], box, tp, fp, first_count=65530)
        from mstrack.hw.vectors import generate
        it = generate(SEQ, [0, 3, 5])
        next(it)
        for rec in it:
            r = rec["trace"]["result"]
            res.append({k: r[k] for k in ("cx", "cy", "rho_c", "rho_e", "alpha_c", "iter_c", "iter_e",
                                          "stop_c", "stop_e")} | {"frame_count": rec["frame"],
                                                                  "flags": 4 * r["lost"]})
    return [pack_result(r) for r in res]


def random_words(n: int, width: int, seed: int) -> list[int]:
    rng = random.Random(seed)
    return [rng.getrandbits(width) for _ in range(n)] + [0, (1 << width) - 1]


def test_decode_v1_matches_python(drv):
    g = core_generics()
    words = model_words() + random_words(300, sum(w for _, _, w in result_layout(g)), 7)
    got = _run(drv, [f"word {_words(w)}" for w in words])
    for w, c in zip(words, got):
        exp = unpack_result(w, g)
        assert {k: c[k] for k in COMPARED_FIELDS} == {k: exp[k] for k in COMPARED_FIELDS}, hex(w)
        assert c["valid"] == 1


def test_decode_v2_matches_python(drv):
    names = [n for n, _, _ in result_layout_v2()]
    words = random_words(300, sum(w for _, _, w in result_layout_v2()), 8)
    got = _run(drv, [f"word2 {_words(w)}" for w in words])
    for w, c in zip(words, got):
        exp = unpack_result_v2(w)
        assert {k: c[k] for k in names} == {k: exp[k] for k in names}, hex(w)


def _regs_of(fields: dict[str, int], m) -> dict[int, int]:
    """Register values ms_tracker_axi shows for one result (encoded with the RDL's fields)."""
    return {
        m["RES_HEAD"].offset: m["RES_HEAD"].encode(frame_count=fields["frame_count"], flags=fields["flags"],
                                                   err_code=fields["err_code"], valid=1),
        m["RES_CX"].offset: fields["cx"], m["RES_CY"].offset: fields["cy"],
        m["RES_RHO_C"].offset: fields["rho_c"], m["RES_RHO_E"].offset: fields["rho_e"],
        m["RES_ALPHA"].offset: fields["alpha_c"],
        m["RES_ITER"].offset: m["RES_ITER"].encode(**{k: fields[k] for k in ("iter_c", "iter_e", "stop_c", "stop_e")}),
        m["RES_BOX"].offset: m["RES_BOX"].encode(box_w=fields["box_w"], box_h=fields["box_h"]),
    }


def test_read_result_and_irq(drv):
    """mstrack_read_result / mstrack_irq_handler on a fake register file holding model results."""
    m = register_map()
    g = core_generics()
    words = model_words()[:8] + random_words(20, sum(w for _, _, w in result_layout(g)), 9)
    lines, exp = [], []
    for w in words:
        f = unpack_result(w, g)
        regs_ = _regs_of(f, m)
        lines.append("regs " + " ".join(f"{o:x}={v:x}" for o, v in regs_.items()))
        lines.append("read")
        exp.append(f)
    got = _run(drv, lines)
    for f, ok, c in zip(exp, got[0::2], got[1::2]):
        assert c["rc"] == 0 and c["valid"] == 1
        assert {k: c[k] for k in COMPARED_FIELDS} == {k: f[k] for k in COMPARED_FIELDS}
    # irq: bits seen are returned and written back (W1C); result read on a result interrupt
    st = m["INT_STATUS"]
    f = exp[0]
    got = _run(drv, [lines[0], f"regs {st.offset:x}={st.encode(result=1, error=1):x}", "irq",
                     f"regs {st.offset:x}=0", "irq", f"regs {m['RES_HEAD'].offset:x}=0", "read"])[1:]
    assert got[1]["st"] == got[1]["written"] == st.encode(result=1, error=1)
    assert {k: got[1][k] for k in COMPARED_FIELDS} == {k: f[k] for k in COMPARED_FIELDS}
    assert got[3]["st"] == 0
    assert got[5]["rc"] == -4 and got[5]["valid"] == 0            # MSTRACK_NO_RESULT


def test_init_and_start(drv):
    m = register_map()
    ident = {m["ID"].offset: 0x4D53544B, m["VERSION"].offset: m["VERSION"].encode(map_major=1, result_version=1),
             m["FORMAT"].offset: m["FORMAT"].encode(max_frame_w=1024)}
    setup = "regs " + " ".join(f"{o:x}={v:x}" for o, v in ident.items())
    got = _run(drv, [f"regs {m['ID'].offset:x}=0", "init 640 480", setup, "init 640 480", "init 2000 480",
                     setup, "init 320 240", "start -5 10 20 30 3", "start 40000 0 1 1 0"])
    assert got[1]["rc"] == -1                                         # no core
    c = got[3]
    assert c["rc"] == 0 and c["FRAME_SIZE"] == m["FRAME_SIZE"].encode(width=640, height=480)
    assert c["CTRL"] == 0 and c["CMD"] == m["CMD"].encode(clear_counters=1)
    assert c["INT_STATUS"] == m["INT_STATUS"].encode(result=1, lost=1, error=1, reacquired=1, command=1)
    assert c["RV"] == 1
    assert got[4]["rc"] == -3                                         # wider than max_frame_w
    s = got[7]
    assert s["rc"] == 0 and s["INIT_POS"] == m["INIT_POS"].encode(x=(-5) & 0xFFFF, y=10)
    assert s["INIT_SIZE"] == m["INIT_SIZE"].encode(width=20, height=30)
    assert s["CMD"] == m["CMD"].encode(init=1) and s["INT_ENABLE"] == 3 and s["CTRL"] == 1
    assert got[8]["rc"] == -3


# ----------------------------------------------------------------------------- core v2 (PRESET 1)
def model_words_v2() -> list[int]:
    """Result words v2 of the fixed-point model on a synthetic scene (init + tracking frames)."""
    from mstrack.fixed import pack_result_v2
    from mstrack.hw.cosim import expected_results_v2
    from mstrack.io.synthetic import make_scene
    frames, _ = make_scene(5, 96, 72, seed=3)
    return [pack_result_v2(r) for r in expected_results_v2(frames, (17, 34, 24, 24), first_count=65533)]


def _regs_of_v2(f: dict[str, int], m) -> dict[int, int]:
    """Register values ms_tracker_axi (PRESET 1) shows for one result word v2 (encoded with the RDL's
    fields); the v1-only registers read 0."""
    return {
        m["RES_HEAD"].offset: m["RES_HEAD"].encode(frame_count=f["frame_count"], flags=f["flags"],
                                                   err_code=f["err_code"], valid=1),
        m["RES_CX"].offset: f["cx"], m["RES_CY"].offset: f["cy"], m["RES_RHO_C"].offset: f["rho"],
        m["RES_RHO_E"].offset: 0, m["RES_ALPHA"].offset: 0, m["RES_ITER"].offset: 0, m["RES_BOX"].offset: 0,
        m["RES_W8"].offset: f["w8"], m["RES_H8"].offset: f["h8"], m["RES_CONF"].offset: f["confidence"],
        m["RES_STATE"].offset: m["RES_STATE"].encode(**{k: f[k] for k in ("status", "iter", "stop", "decim_log2",
                                                                         "searched")}),
    }


def test_read_result_v2_and_irq(drv):
    """Core v2: mstrack_init accepts result word 2, mstrack_read_result_v2 and mstrack_irq_handler read
    every field of model and random words v2 from a fake register file laid out as ms_tracker_axi's."""
    m = register_map()
    names = [n for n, _, _ in result_layout_v2()]
    words = model_words_v2() + random_words(20, sum(w for _, _, w in result_layout_v2()), 10)
    ident = {m["ID"].offset: 0x4D53544B, m["VERSION"].offset: m["VERSION"].encode(map_major=1, map_minor=1,
                                                                                  result_version=2),
             m["FORMAT"].offset: m["FORMAT"].encode(max_frame_w=1024)}
    setup = "regs " + " ".join(f"{o:x}={v:x}" for o, v in ident.items())
    lines, exp = [setup, "init 320 240"], []
    for w in words:
        f = unpack_result_v2(w)
        lines.append("regs " + " ".join(f"{o:x}={v:x}" for o, v in _regs_of_v2(f, m).items()))
        lines.append("read2")
        exp.append(f)
    st = m["INT_STATUS"]
    bits = st.encode(result=1, lost=1, reacquired=1)
    lines += [f"regs {st.offset:x}={bits:x}", "irq2"]
    got = _run(drv, lines)
    assert got[1]["rc"] == 0 and got[1]["RV"] == 2
    for f, c in zip(exp, got[3:-2:2]):
        assert c["rc"] == 0 and c["valid"] == 1
        assert {k: c[k] for k in names} == {k: f[k] for k in names}
    last = got[-1]                                   # the handler on the last word's registers
    assert last["st"] == last["written"] == bits
    assert {k: last[k] for k in names} == {k: exp[-1][k] for k in names} and last["valid"] == 1
    assert last["rho_c"] == exp[-1]["rho"] and last["box_w"] == 0
    # result word 3 is refused
    bad = m["VERSION"].encode(map_major=1, result_version=3)
    assert _run(drv, [setup, f"regs {m['VERSION'].offset:x}={bad:x}", "init 320 240"])[2]["rc"] == -2


# ----------------------------------------------------------------------------- multi-target cores
def test_multi_target_calls(drv):
    """mstrack_add / mstrack_remove / mstrack_read_frame / the handler of a multi-target core on a fake
    register file: the registers written, the report read from CMD_STATUS (id, refused, never answered),
    the calls refused on a single-target core and for an id out of range, a frame read whole or found
    torn (a word's frame_count differs from RES_MASK's), a rejected box seen by the handler."""
    m = register_map()
    cs, head, mask, st = m["CMD_STATUS"], m["RES_HEAD"], m["RES_MASK"], m["INT_STATUS"]

    def regs(**kv):
        return "regs " + " ".join(f"{m[k].offset:x}={v:x}" for k, v in kv.items())
    got = _run(drv, [
        "slots 0", "add 1 2 3 4", "remove 0",                                        # single-target core
        "slots 4", regs(CMD_STATUS=cs.encode(pending=0, code=0, id=2), CMD=0), "add -5 7 30 40",
        regs(CMD_STATUS=cs.encode(pending=0, code=1, id=0), CMD=0), "add 1 1 8 8",  # no free slot
        regs(CMD_STATUS=cs.encode(pending=1), CMD=0), "add 1 1 8 8",                # never reported
        regs(CMD_STATUS=cs.encode(pending=0, code=0, id=1), CMD=0), "remove 1", "remove 4",
        regs(CMD_STATUS=cs.encode(pending=0, code=1, id=3)), "remove 3",            # not live
        regs(RES_MASK=mask.encode(mask=0b101, frame_count=7), RES_HEAD=head.encode(frame_count=7, valid=1, target_id=2),
             RES_CX=1234), "frame",
        regs(RES_HEAD=head.encode(frame_count=6, valid=1)), "frame",                # a frame completed meanwhile
        regs(INT_STATUS=st.encode(command=1), CMD_STATUS=cs.encode(code=3, id=2)), "irqm",
        regs(INT_STATUS=st.encode(result=1), RES_HEAD=head.encode(frame_count=7, valid=1)), "irqm"])
    assert got[1]["rc"] == got[2]["rc"] == -7                                  # MSTRACK_ERR_SINGLE
    a = got[5]
    assert a["rc"] == 0 and a["id"] == 2 and a["CMD"] == m["CMD"].encode(add=1)
    assert a["INIT_POS"] == m["INIT_POS"].encode(x=(-5) & 0xFFFF, y=7) and a["INIT_SIZE"] == m["INIT_SIZE"].encode(width=30, height=40)
    assert got[7]["rc"] == -5 and got[9]["rc"] == -6                           # FULL, TIMEOUT
    r = got[11]
    assert r["rc"] == 0 and r["TARGET"] == 1 and r["CMD"] == m["CMD"].encode(remove=1)
    assert got[12]["rc"] == -3 and got[14]["rc"] == -3                          # id >= slots; not live
    f = got[16]
    assert f["rc"] == 0 and f["mask"] == 0b101 and f["RES_SEL"] == 2 and f["t0"] == f["t2"] == 1234
    assert f["i0"] == f["i2"] == 2                                             # (the fake RES_HEAD's target_id)
    assert got[18]["rc"] == -8 and got[18]["mask"] == 0                        # MSTRACK_ERR_TORN
    assert got[20]["st"] == st.encode(command=1) and got[20]["box_rejected"] == 0b100
    assert got[22]["st"] == st.encode(result=1) and got[22]["mask"] == 0b101
