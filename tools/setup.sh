#!/usr/bin/env bash
# Create .venv with Python 3.11 and install the locked dependencies and the package.
# Idempotent: re-running only installs what changed.
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3.11}
command -v "$PY" >/dev/null 2>&1 || PY=python3
"$PY" -c 'import sys; assert sys.version_info[:2] == (3, 11), f"Python 3.11 required, found {sys.version.split()[0]}"'
[ -x .venv/bin/python ] || "$PY" -m venv .venv
.venv/bin/python -m pip install --quiet --disable-pip-version-check -r requirements.lock
.venv/bin/python -m pip install --quiet --disable-pip-version-check --no-deps -e .

# TeX for the manuscript (rule paper: latexmk, pdflatex, REVTeX 4.2) and poppler-utils for its check
# (pdftotext, pdfinfo), from the Debian packages. Only as root and only if missing; without them
# every target but the PDF builds, and the paper rule says what to install.
TEX_PACKAGES="latexmk texlive-publishers texlive-latex-recommended poppler-utils"
if ! command -v latexmk >/dev/null 2>&1 || ! command -v pdftotext >/dev/null 2>&1 \
    || ! kpsewhich revtex4-2.cls >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "setup: installing TeX for the paper ($TEX_PACKAGES)"
        apt-get update -qq >/dev/null
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $TEX_PACKAGES >/dev/null
    else
        echo "setup: note: TeX is missing, so the paper PDF will not build;" \
             "install as root: apt-get install $TEX_PACKAGES" >&2
    fi
fi
