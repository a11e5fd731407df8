#!/usr/bin/env bash
# Writes bash completion for rigc, made from the binary's own help: the verbs of `rigc --help`,
# each verb's options from `rigc VERB --help` and the values of options that list them
# ({preview,povray,cycles}); anything else completes as a file name.
#
# Usage: bash scripts/completion.sh [RIGC] > ~/.local/share/bash-completion/completions/rigc
#        (or `source` the output from ~/.bashrc). RIGC defaults to ./build/rigc.
set -euo pipefail
rigc=${1:-./build/rigc}
verbs=$("$rigc" --help | sed -n 's/^  \([a-z][a-z]*\)  .*/\1/p')

/usr/bin/python3 - "$rigc" $verbs <<'PY'
import re, shlex, subprocess, sys

rigc, verbs = sys.argv[1], sys.argv[2:]
options, values = {}, {}
for verb in verbs:
    text = subprocess.run([rigc, verb, "--help"], capture_output=True, text=True).stdout
    names = []
    for line in text.splitlines():
        m = re.match(r"^  ((?:-\w,)?(--[\w-]+)(?:,--[\w-]+)*)\S*", line)
        if not m:
            continue
        for name in m.group(1).split(","):
            names.append(name.lstrip("!"))
        choice = re.search(r"\{([\w,.-]+)\}", line)
        if choice and "->" not in line and choice.group(1) not in ("false", "true"):
            values[(verb, m.group(2))] = choice.group(1).replace(",", " ")
    options[verb] = " ".join(names)

print("# bash completion for rigc, written by scripts/completion.sh from rigc's help.")
print("_rigc() {")
print('  local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]}')
print("  if (( COMP_CWORD == 1 )); then")
print(f'    COMPREPLY=($(compgen -W {shlex.quote(" ".join(verbs))} -- "$cur"))')
print("    return")
print("  fi")
print('  case "${COMP_WORDS[1]} $prev" in')
for (verb, option), words in sorted(values.items()):
    print(f'    {shlex.quote(verb + " " + option)}) COMPREPLY=($(compgen -W {shlex.quote(words)} -- "$cur")); return ;;')
print("  esac")
print('  if [[ $cur == -* ]]; then')
print('    case "${COMP_WORDS[1]}" in')
for verb, names in options.items():
    print(f'      {verb}) COMPREPLY=($(compgen -W {shlex.quote(names)} -- "$cur")) ;;')
print("    esac")
print("    return")
print("  fi")
print('  COMPREPLY=($(compgen -f -- "$cur"))')
print("}")
print("complete -o filenames -o bashdefault -F _rigc rigc")
PY
