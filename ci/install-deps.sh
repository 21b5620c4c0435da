#!/usr/bin/env bash
# Installs granular-shaker's build, test and plot dependencies from Debian 12 packages.
# Idempotent: packages already present are left alone and apt-get is not called at all.
#
#   ci/install-deps.sh             what ci/test.sh and ci/base-case.sh need (the default set)
#   ci/install-deps.sh --nightly   also what only the nightly tests need (ci/nightly runs this):
#                                  ParaView, whose XDMF readers read the 3D fields
#                                  (ctest continuum.FieldsXdmf.ParaView), and Clang with
#                                  libFuzzer for the fuzz targets (preset fuzz)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev libgsl-dev libhdf5-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libtoml11-dev libcli11-dev libfmt-dev
  libopenmpi-dev openmpi-bin
  python3 python3-numpy python3-matplotlib python3-h5py python3-meshio
  python3-pytest python3-flake8 python3-ase
  python3-pip python3-setuptools python3-wheel python3-venv python3-gsd
  python3-nbclient python3-nbformat python3-ipykernel
)
case ${1:-} in
  "") ;;
  --nightly) packages+=(paraview python3-paraview clang libfuzzer-14-dev) ;;
  *) echo "install-deps: unknown argument '$1' (allowed: --nightly)" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
sudo_cmd=()
[ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
