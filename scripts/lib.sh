# Shell helpers sourced by the Makefile recipes (bash).

die() { echo "error: $*" >&2; exit 1; }
step() { echo "==> $*"; }

# apt_install PKG...: apt-get update and install, as root or through sudo when available.
apt_install() {
  command -v apt-get >/dev/null 2>&1 ||
    die "apt-get not found; install $* with the system's package manager"
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null 2>&1 || die "need root or sudo to install $*"
    sudo=(sudo)
  fi
  step "apt-get install $*"
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -q -y update
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get -q -y install --no-install-recommends "$@"
}

# check_stems FILE...: each experiment file's top-level `name:` equals its file stem, since
# its results go to <out>/<name>/ and the recipes find them by the stem.
check_stems() {
  local f stem name
  for f in "$@"; do
    stem=$(basename "$f" .yaml)
    name=$(sed -n -E "s/^name[[:space:]]*:[[:space:]]*[\"']?([^\"'#[:space:]]+)[\"']?[[:space:]]*(#.*)?\$/\1/p" "$f" | head -n 1)
    [ -n "$name" ] || die "$f: no top-level 'name:' line (expected 'name: $stem')"
    [ "$name" = "$stem" ] ||
      die "$f: name '$name' must equal the file stem '$stem' (results go to <out>/<name>/)"
  done
}
