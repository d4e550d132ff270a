#!/usr/bin/env bash
# Installs what grainfrac-yade needs on Debian bookworm, if missing. Idempotent.
# YADE and the scientific stack all come from Debian, so they share one numpy
# and run on Debian's /usr/bin/python3 (whatever python3 is first on PATH).
# slurm-wlm and munge: SLURM's daemons and clients for `submit` / `status`; their tests start their
# own single-node cluster from a generated slurm.conf (nothing is configured here).
# python3-vtk9: VTK's XML writer and reader for the ParaView series (vtk/*.vtp, *.pvd); python3-pil
# (Pillow) and ffmpeg: the GIF and MP4 of `animate`. python3-pytest-xdist: the test command runs the suite on every core
# (`-n logical`, one test file per worker).
set -euo pipefail
PACKAGES="yade python3-numpy python3-scipy python3-pandas python3-matplotlib python3-pytest python3-pytest-xdist git slurm-wlm munge python3-vtk9 python3-pil ffmpeg"
missing=""
for p in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "installing:$missing"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi
/usr/bin/python3 -c "import numpy, scipy, pandas, matplotlib, pytest, xdist, PIL, vtkmodules.vtkIOXML" \
  || { echo "setup.sh: Debian's python3 cannot import the scientific stack; fix: apt-get install $PACKAGES"; exit 1; }
