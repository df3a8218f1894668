#!/usr/bin/env bash
# Writes the API reference of the public headers (Doxyfile) to build/docs/html (or DIR/html):
#   scripts/docs.sh [DIR]
# Needs doxygen (scripts/install-deps.sh installs it). Not part of scripts/test.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
export FOXI_DOCS_DIR=$(mkdir -p "${1:-build/docs}" && cd "${1:-build/docs}" && pwd)
doxygen Doxyfile
echo "docs: $FOXI_DOCS_DIR/html/index.html ($(grep -c . "$FOXI_DOCS_DIR/warnings.log" || true) warnings in $FOXI_DOCS_DIR/warnings.log)"
