# Sourced by the project's scripts: a ROS environment that does not depend on the host.
# - /usr/bin first: a pyenv/conda python3 earlier on PATH breaks catkin and rospy.
# - ROS_HOME inside the build folder (logs, test results, nodes' relative outputs), even when set
#   before: the tests' cached bags and results live there. ROS_HOSTNAME=localhost so nothing
#   depends on the host name resolving, unless ROS_HOSTNAME or ROS_IP is set already: forced, the
#   nodes advertised localhost to a remote rviz, which then listed the topics and got nothing.
# - OMP_WAIT_POLICY=PASSIVE: libtorch's spinning OpenMP threads slow other nodes down 5-15x.
CLOTHWIND_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
CLOTHWIND_BUILD="${CLOTHWIND_BUILD:-$CLOTHWIND_ROOT/build}"
# Absolute: a relative one put a relative folder on PATH and ROS_HOME, wrong after the next cd.
CLOTHWIND_BUILD="$(realpath -ms -- "$CLOTHWIND_BUILD")"  # as scripts/build
# The build's bin first: `clothwind` and the benches by name, as every doc types them.
export PATH="$CLOTHWIND_BUILD/bin:/usr/bin:/bin:/usr/sbin:/sbin:$PATH"
export ROS_HOME="$CLOTHWIND_BUILD/ros_home"
# Sourced again after ROS_IP was set (README's remote rviz), its own earlier localhost goes: ROS
# prefers ROS_HOSTNAME, and the nodes went on saying localhost.
if [ "${CLOTHWIND_SET_ROS_HOSTNAME:-}" = 1 ] && [ "${ROS_HOSTNAME:-}" = localhost ] && [ -n "${ROS_IP:-}" ]; then
  unset ROS_HOSTNAME
fi
if [ -z "${ROS_HOSTNAME:-}" ] && [ -z "${ROS_IP:-}" ]; then
  export ROS_HOSTNAME=localhost CLOTHWIND_SET_ROS_HOSTNAME=1
elif [ "${ROS_HOSTNAME:-}" != localhost ]; then
  unset CLOTHWIND_SET_ROS_HOSTNAME
fi
export ROS_MASTER_URI="${ROS_MASTER_URI:-http://localhost:11311}"
export OMP_WAIT_POLICY=PASSIVE
export PYTHONUNBUFFERED=1
if [ -f "$CLOTHWIND_BUILD/devel/setup.bash" ]; then
  # ROS's setup scripts read unset variables: relax nounset while sourcing them.
  case $- in *u*) _cw_nounset=1; set +u ;; *) _cw_nounset=0 ;; esac
  # shellcheck disable=SC1091
  source "$CLOTHWIND_BUILD/devel/setup.bash"
  [ "$_cw_nounset" = 1 ] && set -u
  unset _cw_nounset
fi
