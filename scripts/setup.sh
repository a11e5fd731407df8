#!/usr/bin/env bash
# Installs every build and run dependency of RigC from Debian's packages.
# Idempotent and non-interactive: packages already present are skipped.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config clang-format
  libyaml-cpp-dev libtinygltf-dev libstb-dev libopenimageio-dev openimageio-tools
  libassimp-dev assimp-testmodels libeigen3-dev libcli11-dev libfmt-dev libssl-dev zlib1g-dev
  nlohmann-json3-dev libtbb-dev libsqlite3-dev libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-jsonschema python3-yaml
  povray blender colmap libopen3d-dev libembree-dev libnanoflann-dev fonts-dejavu-core
  libcpp-httplib-dev libjs-three chromium chromium-driver python3-selenium
  slurmctld slurmd slurm-client munge
  clang libfuzzer-14-dev ccache
)

missing=()
for pkg in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if ((${#missing[@]})); then
  sudo_cmd=()
  if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all packages present"
fi
