#!/usr/bin/env bash
# Lint, format, type and stub checks for CI and before a commit (the same as the pre-commit
# hooks, on the whole tree). Installs the pinned tools of requirements/dev.txt into the active
# environment (not the package itself: the type stub check imports the installed dynid).
#   bash tools/check.sh              # install the tools, then check
#   bash tools/check.sh --no-install # tools already installed
set -euo pipefail
cd "$(dirname "$0")/.."

if [[ "${1:-}" != "--no-install" ]]; then
  python -m pip install -q -r requirements/dev.txt
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
