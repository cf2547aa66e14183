#!/usr/bin/env bash
# Lint, format, type and stub checks for CI and before a commit (the same as the pre-commit
# hooks, on the whole tree). Installs the pinned tools of the `dev` extra into the active
# environment (not the package itself: the type stub check imports the installed dynid).
#   bash tools/check.sh              # install the tools, then check
#   bash tools/check.sh --no-install # tools already installed
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ "${1:-}" != "--no-install" ]]; then
  requirements=$(mktemp)
  # The dev extra of pyproject.toml (tomllib from Python 3.11 on, a plain parse before).
  python - >"$requirements" <<'PY'
import re
from pathlib import Path

text = Path("pyproject.toml").read_text()
try:
    import tomllib

    dev = tomllib.loads(text)["project"]["optional-dependencies"]["dev"]
except ImportError:
    block = re.search(r"^dev = \[(.*?)^\]", text, re.S | re.M).group(1)
    dev = re.findall(r'^\s*"([^"]+)"', block, re.M)
print("\n".join(dev))
PY
  python -m pip install -q -r "$requirements"
  rm -f "$requirements"
fi

targets=(python tests bench tools examples)
failed=()
step() {  # step NAME COMMAND...: run every check, report all failures at the end
  local name=$1
  shift
  echo "== $name"
  if ! "$@"; then failed+=("$name"); fi
}
stub_check() {
  if python -c 'import pybind11_stubgen, dynid._core' 2>/dev/null; then
    python tools/generate_stubs.py --check
  elif [[ -n "${CI:-}" ]]; then
    echo "CI: the stub check needs dynid installed and pybind11-stubgen (Python >= 3.10)" >&2
    return 1
  else
    echo "skipped: needs dynid installed and pybind11-stubgen (Python >= 3.10)"
  fi
}
version=$(python -c 'import sys; print("%d.%d" % sys.version_info[:2])')
mapfile -t cpp_files < <(git ls-files 'cpp/*.cpp' 'cpp/*.hpp' 'tests/cpp/*.cpp' 'tests/cpp/*.hpp')

step "ruff format --check" ruff format --check "${targets[@]}"
step "ruff check" ruff check "${targets[@]}"
step "mypy (python_version 3.9, pyproject.toml)" mypy
step "mypy (python_version $version: the installed NumPy's stubs in full)" \
  mypy --python-version "$version"
step "clang-format" clang-format --dry-run --Werror "${cpp_files[@]}"
step "_core.pyi up to date" stub_check

if ((${#failed[@]})); then
  printf 'check: FAILED: %s\n' "${failed[@]}" >&2
  exit 1
fi
echo "check: all passed"
