# Shared by the shell test scripts (source it): counters and checks.
passed=0
failed=0
ok() { passed=$((passed + 1)); echo "ok   - $1"; }
bad() { failed=$((failed + 1)); echo "FAIL - $1"; }
check() { # check DESCRIPTION COMMAND...
	local d=$1
	shift
	if "$@"; then ok "$d"; else bad "$d"; fi
}
# COMMAND with its output dropped, for check (a redirection after check
# would drop check's own line too)
quiet() { "$@" >/dev/null; }
# whether idiff finds images A and B equal, bit for bit: same A B
same() { quiet idiff -fail 0 -failpercent 0 "$@"; }
# true when awk says so: num 'EXPR' with a=$2 b=$3 c=$4
num() {
	awk -v a="${2:-0}" -v b="${3:-0}" -v c="${4:-0}" "BEGIN { exit !($1) }"
}
