# Shared by the project's scripts (sourced, not run). Knows how this machine builds wasm.
# shellcheck shell=bash

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH="$HOME/.cargo/bin:$PATH"

say() { printf '\033[1m[tspath]\033[0m %s\n' "$*" >&2; }

# The wasm-bindgen version pinned by Cargo.lock (the CLI must match it exactly).
wasm_bindgen_version() {
  awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' "$ROOT/Cargo.lock"
}

# Which route builds wasm32 here: "rustup" (target installed), "debian" (Debian's rustc-web
# with std sources, built with build-std), or "none".
wasm_route() {
  if [ -n "${TSPATH_WASM_ROUTE:-}" ]; then
    echo "$TSPATH_WASM_ROUTE"   # forced, to test a route on a machine that has both
  elif rustup target list --installed 2>/dev/null | grep -qx wasm32-unknown-unknown; then
    echo rustup
  elif [ -x /usr/bin/cargo ] && [ -d /usr/lib/rustlib/src/rust/library ] && command -v rust-lld >/dev/null 2>&1; then
    echo debian
  else
    echo none
  fi
}

# Runs cargo for the wasm32 target by whichever route this machine has.
wasm_cargo() {
  case "$(wasm_route)" in
    rustup) cargo "$@" ;;
    debian)
      # Debian's compiler, std built from source; its own target dir so the two compilers'
      # artefacts do not evict each other.
      PATH="/usr/bin:$PATH" RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR="$ROOT/target/wasm-debian" \
        /usr/bin/cargo "$@" -Zbuild-std=std,panic_abort ;;
    *) say "no wasm32 toolchain: run scripts/setup"; return 1 ;;
  esac
}

# Directory the wasm32 artefacts land in.
wasm_target_dir() {
  case "$(wasm_route)" in
    debian) echo "$ROOT/target/wasm-debian" ;;
    *) echo "$ROOT/target" ;;
  esac
}
