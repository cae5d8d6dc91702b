# Debian packages sgbake needs, sourced by the other scripts. Runs apt-get as root (or via sudo).
#   install_deps build   - what building the library and the CLI needs
#   install_deps test    - plus GoogleTest, Google Benchmark, Blender (the oracle) and numpy
install_deps() {
  local packages="cmake ninja-build g++ pkg-config libopenmesh-dev libosd-dev libopenimageio-dev
    libtbb-dev nlohmann-json3-dev libcli11-dev libeigen3-dev"
  if [ "$1" = test ]; then
    packages="$packages libgtest-dev libgmock-dev libbenchmark-dev blender python3 python3-numpy"
  fi
  local sudo=""
  [ "$(id -u)" = 0 ] || sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  # shellcheck disable=SC2086
  $sudo apt-get install -y -qq --no-install-recommends $packages >/dev/null
}
