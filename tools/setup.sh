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

# A headless browser for the test that opens the 3-D view of a rod (tests/test_view.py), from the
# Debian package. Only as root and only if missing; without it that test is skipped (CI sets
# CI_REQUIRE_BROWSER=1, and then it fails instead).
BROWSER_PACKAGES="chromium fonts-liberation fonts-dejavu-core"
if ! command -v chromium >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
        echo "setup: installing chromium for the browser test of the 3-D view ($BROWSER_PACKAGES)"
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $BROWSER_PACKAGES >/dev/null \
            || { apt-get update -qq >/dev/null \
                 && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $BROWSER_PACKAGES \
                    >/dev/null; } \
            || echo "setup: note: installing chromium failed; the browser test of the 3-D view will not run" >&2
    else
        echo "setup: note: chromium is missing, so the browser test of the 3-D view is skipped;" \
             "install as root: apt-get install $BROWSER_PACKAGES" >&2
    fi
fi
