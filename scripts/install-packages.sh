#!/usr/bin/env bash
# Installs the Debian packages named as arguments that are not installed yet, through apt-get
# (as root, or with sudo). Does nothing when all are present. Every script that needs packages
# (setup.sh, run-tests.sh, run-sanitizers.sh, run-fuzz.sh) calls this one.
# usage: scripts/install-packages.sh LABEL PACKAGE...   (LABEL prefixes the one line it prints)
set -euo pipefail
label="$1"
shift
missing=()
for p in "$@"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -gt 0 ] || exit 0
echo "$label: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
