#!/usr/bin/env bash
# Installs the headless browser the report's browser test drives (Debian's
# `chromium` and `chromium-driver`), when missing. Run by .ci/run before the
# tests and by the test itself (crates/report/tests/browser.rs), so that
# `cargo test --workspace` needs nothing installed by hand. Idempotent:
# prints the paths and exits 0 when both are there already.
set -euo pipefail
have() { command -v "$1" >/dev/null 2>&1; }
if have chromium && have chromedriver; then
    echo "chromium: $(command -v chromium); chromedriver: $(command -v chromedriver)"
    exit 0
fi
if ! have apt-get; then
    echo "install-browser: chromium and chromedriver are missing and apt-get is not available: install them (Debian: chromium, chromium-driver)" >&2
    exit 1
fi
sudo=()
if [ "$(id -u)" != 0 ]; then
    if have sudo; then sudo=(sudo -n); else
        echo "install-browser: not root and no sudo: run 'apt-get install -y chromium chromium-driver' as root" >&2
        exit 1
    fi
fi
export DEBIAN_FRONTEND=noninteractive
# Another apt run (a parallel test) holds the lock: wait for it.
lock=(-o DPkg::Lock::Timeout=600)
if ! "${sudo[@]}" apt-get "${lock[@]}" install -y --no-install-recommends chromium chromium-driver; then
    "${sudo[@]}" apt-get "${lock[@]}" update
    "${sudo[@]}" apt-get "${lock[@]}" install -y --no-install-recommends chromium chromium-driver
fi
echo "chromium: $(command -v chromium); chromedriver: $(command -v chromedriver)"
