# Sourced, not run: the Debian mirror the host's apt already uses, for scripts that bootstrap a
# Debian tree (docker/base-image.sh, tools/fastdds3/chroot.sh), so that a machine whose apt goes
# through another mirror or a proxy builds them through that one too.
#
#   source tools/apt_sources.sh
#   mirror=$(debian_mirror trixie bookworm)   # the first suite that a source serves

# The first URI that apt uses for SUITE, from one-line (.list) or deb822 (.sources) files; nothing
# when no enabled `deb` source lists SUITE.
apt_uri() {
  local suite=$1
  {
    cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
      sed -E 's/\[[^]]*\]//' | awk -v s="$suite" '$1 == "deb" && $3 == s { print $2 }'
    cat /etc/apt/sources.list.d/*.sources 2>/dev/null |
      awk -v s="$suite" 'BEGIN { RS = "" } {
        uri = ""; ok = 0; deb = 0
        n = split($0, lines, "\n")
        for (k = 1; k <= n; k++) {
          if (lines[k] ~ /^Types:/ && lines[k] ~ /[[:space:]]deb([[:space:]]|$)/) deb = 1
          if (lines[k] ~ /^URIs:/) { split(lines[k], f, /[[:space:]]+/); uri = f[2] }
          if (lines[k] ~ /^Suites:/) { m = split(lines[k], f, /[[:space:]]+/); for (i = 2; i <= m; i++) if (f[i] == s) ok = 1 }
          if (lines[k] ~ /^Enabled:[[:space:]]*no/) deb = 0
        }
        if (deb && ok && uri != "") print uri }'
  } | head -n 1
}

# The host's Debian archive: the URI of the first of SUITES... that an apt source serves (a mirror
# that serves one Debian release serves the others); fails when none does.
debian_mirror() {
  local suite uri
  for suite in "$@"; do
    uri=$(apt_uri "$suite")
    if [[ -n $uri ]]; then
      echo "$uri"
      return 0
    fi
  done
  return 1
}
