# shellcheck shell=bash disable=SC2034
# Sourced (from the repository's root) by the scripts that run Python tools from PyPI, and by
# .ci/run: one virtual environment holds them all, target/ci-venv (or THIRDBODY_VENV), since
# Debian's python refuses `pip install` outside one (PEP 668, "externally-managed-
# environment"). `python_tool COMMAND REQUIREMENT...` makes COMMAND available: the one on
# PATH if there is one (.ci/run puts the environment first on PATH), else installed into the
# environment, which then goes first on PATH.

# The tools, with the versions the checks were written against.
KUBERNETES_VALIDATE='kubernetes-validate==1.37.0'
SCHEMATHESIS='schemathesis>=4.3,<5'
OPENAPI_PYTHON_CLIENT='openapi-python-client>=0.26,<1'

venv="${THIRDBODY_VENV:-$PWD/target/ci-venv}"

# Makes the environment if it has no pip yet (python3-venv is needed on Debian), and puts it
# first on PATH.
use_venv() {
  if [ ! -x "$venv/bin/pip" ]; then
    rm -rf "$venv"
    if ! python3 -m venv "$venv"; then
      echo "cannot make a Python virtual environment in $venv:" \
        "install python3-venv (apt-get install python3-venv)" >&2
      return 1
    fi
  fi
  case ":$PATH:" in
    *":$venv/bin:"*) ;;
    *) export PATH="$venv/bin:$PATH" ;;
  esac
  export VIRTUAL_ENV="$venv"
}

# Installs REQUIREMENTs into the environment.
venv_install() {
  use_venv
  "$venv/bin/python" -m pip install --quiet --disable-pip-version-check "$@"
}

# python_tool COMMAND REQUIREMENT...: COMMAND on PATH, installed into the environment if it
# is not there already.
python_tool() {
  local command=$1
  shift
  command -v "$command" >/dev/null || venv_install "$@"
  command -v "$command" >/dev/null || {
    echo "$command is not on PATH after installing $*" >&2
    return 1
  }
}
