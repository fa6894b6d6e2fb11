#!/usr/bin/env bash
# On the GPU machine: keeps this part's files in $HOME/.gmloco-stash; with --install, joins split wheels and
# installs every stashed wheel into $HOME/.gmloco-site (no index, no dependencies, no network).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
stash=$HOME/.gmloco-stash
mkdir -p "$stash"
find "$here" -maxdepth 1 -type f ! -name install_part.sh -exec cp {} "$stash"/ \;
echo "stash: $(ls "$stash" | wc -l) files, $(du -sh "$stash" | cut -f1)"
if [ "${1:-}" = "--install" ]; then
  cd "$stash"
  for first in *.piece.00; do
    [ -e "$first" ] || continue
    cat "${first%.piece.00}".piece.* > "${first%.piece.00}" && rm "${first%.piece.00}".piece.*
  done
  python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade \
    --target "$HOME/.gmloco-site" ./*.whl
  echo "installed into $HOME/.gmloco-site"
fi
