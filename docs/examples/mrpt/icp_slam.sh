#!/bin/sh
# Run MRPT's icp-slam offline over a CARMEN log and write its trajectory as a TUM file.
#
#   sh icp_slam.sh INPUT.clf OUTPUT.tum [WORKDIR]
#
# INPUT: a CARMEN log (FLASER, RLASER or ROBOTLASER1 lines; the odometry is their second pose
# triple, ODOM lines are not read). OUTPUT: one `t x y z qx qy qz qw` line per laser line, t = that
# line's ipc_timestamp. WORKDIR (default: a temporary folder, removed afterwards) receives the rawlog,
# icp-slam's log (icp-slam.log) and its output folder icp_out/ (map, paths).
# Environment: ICP_SLAM_INI (default: icp_slam.ini next to this script), MRPT_TIMEOUT (s, default 3600),
# PYTHON (default: python3).
set -u

die() { echo "icp_slam.sh: $*" >&2; exit 1; }
# The gist of an MRPT tool's log (its exception message, else the last lines) on stderr.
said() { grep -E -m 3 'Message:|[Ee]rror|Assert' "$1" >&2 || tail -n 5 "$1" >&2; }
abs() { case "$1" in /*) echo "$1" ;; *) echo "$PWD/$1" ;; esac; }

[ $# -ge 2 ] && [ $# -le 3 ] || die "usage: sh icp_slam.sh INPUT.clf OUTPUT.tum [WORKDIR]"
here=$(cd "$(dirname "$0")" && pwd) || die "cannot find the script's folder"
input=$(abs "$1")
output=$(abs "$2")
ini=$(abs "${ICP_SLAM_INI:-$here/icp_slam.ini}")
python=${PYTHON:-python3}
timeout=${MRPT_TIMEOUT:-3600}
[ -f "$input" ] || die "no input log: $input"
[ -f "$ini" ] || die "no config file: $ini"
for p in carmen2rawlog icp-slam timeout "$python"; do
    command -v "$p" >/dev/null 2>&1 || die "'$p' not found (MRPT's tools: apt-get install mrpt-apps)"
done
if [ $# -eq 3 ]; then
    work=$(abs "$3")
    mkdir -p "$work" || die "cannot make $work"
else
    work=$(mktemp -d) || die "cannot make a temporary folder"
    trap 'rm -rf "$work"' EXIT
fi
cd "$work" || die "cannot enter $work"

# MRPT's tools wait for a key press after an error: stdin from /dev/null and a timeout guard them.
# 1. CARMEN -> rawlog (observations: odometry + laser scan per laser line; -z 0: uncompressed).
timeout "$timeout" carmen2rawlog -q -w -z 0 -i "$input" -o log.rawlog </dev/null >carmen2rawlog.log 2>&1 ||
    { said carmen2rawlog.log; die "carmen2rawlog failed"; }
# 2. carmen2rawlog stamps every observation with the same time: give them the log's times.
"$python" "$here/mrpt_adapter.py" stamp "$input" log.rawlog || die "could not fix the rawlog's timestamps"
# 3. icp-slam; it writes icp_out/ (logOutput_dir in the ini), relative to this folder.
timeout "$timeout" icp-slam "$ini" log.rawlog </dev/null >icp-slam.log 2>&1 ||
    { said icp-slam.log; die "icp-slam failed (full log: icp-slam.log in the WORKDIR)"; }
[ -s icp_out/log_estimated_path.txt ] || die "icp-slam wrote no icp_out/log_estimated_path.txt"
# 4. Its per-observation path -> TUM, with the laser lines' timestamps.
"$python" "$here/mrpt_adapter.py" tum "$input" icp_out/log_estimated_path.txt "$output" ||
    die "could not write $output"
