#!/usr/bin/env bash
# Installs what ReactHuman needs on a fresh Debian/Ubuntu machine. Idempotent: packages
# already present are skipped, so running it again is cheap.
set -euo pipefail

apt_packages=(
  mesa-vulkan-drivers libvulkan1
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev
  libavfilter-dev libavdevice-dev libswresample-dev
  clang libclang-dev pkg-config ffmpeg
  cmake nasm
  python3 python3-pip python3-venv
  chromium
  slurm-wlm munge
  # Real meshes of catalog objects (issue 45): Sweet Home 3D's furniture libraries
  # (OBJ/MTL models with textures, CC0 and CC-BY), read by rendered builds only.
  sweethome3d-furniture
)
# Import names. The Python package's build and tests (scripts/test_python.sh) need
# maturin, numpy, gymnasium and pytest; its wheel's own dependencies are numpy, pyarrow
# and gymnasium. jsonschema validates results files in tests/tests/results_leaderboard.rs.
python_packages=(pyarrow datasets maturin numpy gymnasium pytest jsonschema)
# Modules whose pip package has another name or a version floor (module:package): Pillow
# decodes the `datasets` Image columns of rendered builds (`<cam>_frames`); pyyaml and
# bibtexparser 2 parse the dataset card's front matter and citations
# (tests/tests/dataset_build.rs).
python_renamed=(PIL:pillow yaml:pyyaml "bibtexparser:bibtexparser>=2")

missing=()
for pkg in "${apt_packages[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done

if [ ${#missing[@]} -gt 0 ]; then
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null || { echo "setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
    sudo_cmd=(sudo)
  fi
  echo "setup: installing system packages: ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

py_missing=()
for mod in "${python_packages[@]}"; do
  python3 -c "import $mod" 2>/dev/null || py_missing+=("$mod")
done
for pair in "${python_renamed[@]}"; do
  python3 -c "import ${pair%%:*}" 2>/dev/null || py_missing+=("${pair#*:}")
done
if [ ${#py_missing[@]} -gt 0 ]; then
  echo "setup: installing Python packages: ${py_missing[*]}"
  python3 -m pip install --quiet --disable-pip-version-check "${py_missing[@]}" \
    || python3 -m pip install --quiet --disable-pip-version-check --break-system-packages "${py_missing[@]}"
fi

# Offline Kubernetes Job schema validation (tests/tests/cluster_manifests.rs); its import
# name differs from the package's, so it has its own check.
if ! python3 -c "import kubernetes_validate" 2>/dev/null; then
  echo "setup: installing Python package: kubernetes-validate"
  python3 -m pip install --quiet --disable-pip-version-check kubernetes-validate \
    || python3 -m pip install --quiet --disable-pip-version-check --break-system-packages kubernetes-validate
fi

# inspect_ai for the harness integration (integrations/inspect_ai; tested offline by
# python/tests/test_inspect.py with its mock model), pinned: the task is written against
# this version's Task / scorer / mockllm API.
inspect_version=0.3.285
if [ "$(python3 -c 'import inspect_ai; print(inspect_ai.__version__)' 2>/dev/null)" != "$inspect_version" ]; then
  echo "setup: installing Python package: inspect_ai==$inspect_version"
  python3 -m pip install --quiet --disable-pip-version-check "inspect_ai==$inspect_version" \
    || python3 -m pip install --quiet --disable-pip-version-check --break-system-packages "inspect_ai==$inspect_version"
fi

command -v cargo >/dev/null || { echo "setup: cargo not found; install Rust (rustup) first" >&2; exit 1; }
echo "setup: ok"
