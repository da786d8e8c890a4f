#!/usr/bin/env bash
# Installs what the test suite needs: vares with its test extras, and Debian's Chromium for
# the test that opens the HTML report in a real headless browser.
set -euo pipefail
cd "$(dirname "$0")/.."
pip install -e ".[test]"
if ! command -v chromium >/dev/null 2>&1; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "chromium is missing: install Debian's package 'chromium' (needs root)" >&2
        exit 1
    fi
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y chromium
fi
