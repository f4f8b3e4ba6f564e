#!/usr/bin/env bash
# Installs every build and test dependency of gpubridge from Debian 12 packages.
# Idempotent: re-running it only refreshes the package lists and installs what is missing.
set -euo pipefail

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

packages=(
  build-essential cmake pkg-config git ninja-build
  clang libclang-rt-14-dev                    
  libboost-dev libboost-system-dev            
  libusb-1.0-0-dev libhidapi-dev              
  libglfw3-dev libgl-dev libegl-dev libopengl-dev libgl1-mesa-dri libegl-mesa0
  nlohmann-json3-dev libspdlog-dev libfmt-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libpng-dev zlib1g-dev
  libzstd-dev libssl-dev                      
  libsystemd-dev                              
  umockdev libumockdev-dev                    
  xvfb xauth x11-utils                        
  verilator yosys                             # gateware: rtl backend, ctest -L rtl (lint, co-simulation, yosys read)
  iverilog                                    # gateware: rtl.dsp_counter (the SB_MAC16 model against yosys's)
  nextpnr-ice40 fpga-icestorm                 # gateware: iCE40 place and route, icepack (docs/gateware.md)
  python3                                     # scripts/gateware.sh (gateware/boards/build.py), gateware/synth.py
  openfpgaloader                              # gpubridge flash (iceprog comes with fpga-icestorm)
)

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
echo "install-deps: all ${#packages[@]} packages present"
