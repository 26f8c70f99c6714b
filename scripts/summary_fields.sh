# Sourced by the study scripts: read fields of a run's summary.json without a JSON tool.
# summary_number KEY FILE: the first numeric value of "KEY":
summary_number() {
  grep -o "\"$1\": *[-0-9.eE+]*" "$2" | head -1 | sed 's/.*: *//'
}
# summary_status FILE: the run's status (finished, stopped)
summary_status() {
  grep -o '"status": *"[a-z]*"' "$1" | head -1 | sed 's/.*: *"//; s/"//'
}
