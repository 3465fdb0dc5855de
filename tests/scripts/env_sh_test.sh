#!/usr/bin/env bash
# Test of scripts/env.sh's ROS network settings: ROS_HOSTNAME=localhost when neither ROS_HOSTNAME
# nor ROS_IP is set (tests never depend on the host name resolving), and a ROS_HOSTNAME or ROS_IP
# set before kept (forced to localhost, the nodes told a remote rviz `localhost`: it listed the
# topics and received nothing); ROS_MASTER_URI kept when set. Usage: env_sh_test.sh BUILD_DIR
set -euo pipefail
build="$1"
env_sh="$(dirname "$0")/../../scripts/env.sh"
fail() { echo "env_sh_test: FAIL: $*" >&2; exit 1; }

# Prints ROS_HOSTNAME|ROS_IP|ROS_MASTER_URI after sourcing env.sh under `set -u` in a clean
# environment holding only the given VAR=VALUE pairs.
after() {
  env -i HOME="$HOME" PATH=/usr/bin:/bin CLOTHWIND_BUILD="$build" "$@" bash -c \
    'set -u; source "$0"; echo "${ROS_HOSTNAME:-}|${ROS_IP:-}|${ROS_MASTER_URI:-}"' "$env_sh"
}

got="$(after)"
[ "$got" = "localhost||http://localhost:11311" ] || fail "nothing set before: $got"
got="$(after ROS_IP=192.0.2.7)"
[ "$got" = "|192.0.2.7|http://localhost:11311" ] || fail "ROS_IP set before: $got"
got="$(after ROS_HOSTNAME=flagpole.local ROS_MASTER_URI=http://base:11311)"
[ "$got" = "flagpole.local||http://base:11311" ] || fail "ROS_HOSTNAME and ROS_MASTER_URI set before: $got"
# Sourced once (a .bashrc), then again after the README's `export ROS_IP=...`: its own localhost
# goes (ROS prefers ROS_HOSTNAME, so the nodes went on saying localhost); a user's own stays.
got="$(env -i HOME="$HOME" PATH=/usr/bin:/bin CLOTHWIND_BUILD="$build" bash -c \
  'set -u; source "$0"; export ROS_IP=192.0.2.9; source "$0"; echo "${ROS_HOSTNAME:-}|${ROS_IP:-}"' "$env_sh")"
[ "$got" = "|192.0.2.9" ] || fail "sourced again after ROS_IP was set: $got"
got="$(env -i HOME="$HOME" PATH=/usr/bin:/bin CLOTHWIND_BUILD="$build" bash -c \
  'set -u; export ROS_HOSTNAME=flagpole.local; source "$0"; export ROS_IP=192.0.2.9; source "$0"; echo "${ROS_HOSTNAME:-}"' \
  "$env_sh")"
[ "$got" = "flagpole.local" ] || fail "a user's ROS_HOSTNAME, sourced twice: $got"
echo "env_sh_test: OK"
