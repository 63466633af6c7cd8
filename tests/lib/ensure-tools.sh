# Sourced by tests/run and the demo: installs what a fresh machine lacks. Each step is idempotent
# and quiet when the tool is already there.

# The Cortex-M4F target (RUSTUP_AUTO_INSTALL may be 0, so rust-toolchain.toml alone won't fetch it).
ensure_thumb_target() {
  if ! rustup target list --installed 2>/dev/null | grep -qx thumbv7em-none-eabihf; then
    echo "== installing the thumbv7em-none-eabihf target"
    rustup target add thumbv7em-none-eabihf
  fi
}

# flip-link is the thumb linker (.cargo/config.toml).
ensure_flip_link() {
  if ! command -v flip-link >/dev/null; then
    echo "== installing flip-link"
    cargo install flip-link --locked --quiet
  fi
}

# qemu-system-arm from Debian bookworm-backports: bookworm's own 7.2 conflicts with the
# preinstalled qemu-utils 10.0 from backports. A private APT source list names the suite, so the
# machine's APT configuration is left as it was.
ensure_qemu() {
  if command -v qemu-system-arm >/dev/null; then
    return 0
  fi
  echo "== installing qemu-system-arm (bookworm-backports)"
  local sudo=""
  if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
  local list
  list=$(mktemp)
  echo 'deb http://deb.debian.org/debian bookworm-backports main' >"$list"
  $sudo apt-get update -qq -o Dir::Etc::sourcelist="$list" >/dev/null &&
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends \
      -o Dir::Etc::sourcelist="$list" -t bookworm-backports qemu-system-arm >/dev/null
  local status=$?
  rm -f "$list"
  return $status
}

# The emulated Black Pill (tests/blackpill): a venv under target/ with the pinned qiling and
# unicorn (tests/blackpill/requirements.txt), and defmt-print to decode the image's logs.
# Sets BLACKPILL_PYTHON and DEFMT_PRINT for the caller. With ENSURE_VERBOSE set (the demo and
# `bowl-emulator`'s boot of the board: emulator/src/blackpill.rs `install`) pip shows its progress.
ensure_blackpill_emulator() {
  local venv=target/venv-blackpill
  local req=tests/blackpill/requirements.txt
  local pip_output=(--quiet)
  if [ -n "${ENSURE_VERBOSE:-}" ]; then pip_output=(--progress-bar on); fi
  if ! [ -x "$venv/bin/python" ] || ! cmp -s "$req" "$venv/requirements.txt"; then
    echo "== installing the Black Pill emulator (qiling, pinned unicorn) into $venv"
    python3 -m venv "$venv" &&
      "$venv/bin/pip" install "${pip_output[@]}" --disable-pip-version-check -r "$req" &&
      cp "$req" "$venv/requirements.txt" || return 1
  fi
  BLACKPILL_PYTHON=$venv/bin/python
  if command -v defmt-print >/dev/null; then
    DEFMT_PRINT=$(command -v defmt-print)
  else
    if ! [ -x target/defmt-tools/bin/defmt-print ]; then
      echo "== installing defmt-print"
      cargo install defmt-print --locked --quiet --root target/defmt-tools || return 1
    fi
    DEFMT_PRINT=$PWD/target/defmt-tools/bin/defmt-print
  fi
  export BLACKPILL_PYTHON DEFMT_PRINT
}

# apt_install PACKAGE...: installs Debian packages (apt-get update first), quietly.
apt_install() {
  local sudo=""
  if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq >/dev/null &&
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "$@" >/dev/null
}

# The Windows build check: the x86_64-pc-windows-gnu target and its MinGW-w64 linker.
ensure_windows_target() {
  if ! command -v x86_64-w64-mingw32-gcc >/dev/null; then
    echo "== installing mingw-w64"
    apt_install mingw-w64 || return 1
  fi
  if ! rustup target list --installed 2>/dev/null | grep -qx x86_64-pc-windows-gnu; then
    echo "== installing the x86_64-pc-windows-gnu target"
    rustup target add x86_64-pc-windows-gnu
  fi
}

# tmux drives the terminal UI in the console tests.
ensure_tmux() {
  if ! command -v tmux >/dev/null; then
    echo "== installing tmux"
    apt_install tmux
  fi
}

# The plain serial consoles a person at the bench uses (host-tools/tests/plain_console.rs
# types commands into them against the virtual rig).
ensure_plain_consoles() {
  if ! command -v picocom >/dev/null || ! command -v tio >/dev/null; then
    echo "== installing picocom and tio"
    apt_install picocom tio
  fi
}
