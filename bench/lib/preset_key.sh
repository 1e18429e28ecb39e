# Sourced by the bench scripts.
# preset_with_key PRESET_YAML SECTION KEY VALUE OUT_YAML: writes the preset with SECTION.KEY set to
# VALUE (the key's line replaced, or added under the section's header when the preset leaves the
# key at its default). Fails, naming the preset, when it has no such section.
preset_with_key() {
  local preset=$1 section=$2 key=$3 value=$4 file=$5
  awk -v section="$section:" -v key="$key" -v value="$value" '
    $0 == section { in_section = 1; print; print "  " key ": " value; next }
    /^[^ #]/ { in_section = 0 }
    in_section && $1 == key ":" { next }
    { print }' "$preset" > "$file"
  grep -q "^  $key: $value\$" "$file" || { echo "$(basename "$0"): no section $section: in $preset" >&2; return 2; }
}
