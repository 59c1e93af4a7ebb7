# Sourced by setup.sh and fuzz.sh: apt_install WHO PACKAGE... installs the packages as root,
# through sudo when not root, quietly; WHO prefixes the messages.
apt_install() {
  local who=$1
  shift
  local sudo_cmd=()
  if [[ $(id -u) -ne 0 ]]; then
    command -v sudo >/dev/null || { echo "$who: need root or sudo to install $*" >&2; exit 1; }
    sudo_cmd=(sudo)
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}
