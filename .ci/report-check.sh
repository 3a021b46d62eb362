#!/usr/bin/env bash
# Render a campaign report in headless Chromium at 1280 px and check that every <svg>
# is laid out with a non-zero size and that the page does not scroll sideways.
#
#   .ci/report-check.sh out/campaign/report.html
#
# Needs Debian's `chromium` (apt-get install -y chromium). The shipped report has no
# script: the check injects one into a copy, which writes the counts into the DOM that
# `--dump-dom` prints.
set -euo pipefail

report=${1:?usage: .ci/report-check.sh REPORT.html}
[ -f "$report" ] || { echo "report-check: no such file: $report" >&2; exit 1; }
browser=${CHROMIUM:-$(command -v chromium || command -v chromium-browser || true)}
[ -n "$browser" ] || { echo "report-check: chromium not found (apt-get install -y chromium)" >&2; exit 1; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
copy="$work/report.html"
probe='<script>
window.addEventListener("load", function () {
  var svgs = Array.prototype.slice.call(document.querySelectorAll("svg"));
  var visible = svgs.filter(function (s) {
    var r = s.getBoundingClientRect();
    return r.width > 0 && r.height > 0;
  }).length;
  var out = document.createElement("pre");
  out.textContent = "REPORT-CHECK svg=" + svgs.length + " visible=" + visible +
    " scrollWidth=" + document.documentElement.scrollWidth;
  document.body.appendChild(out);
});
</script>'
# Insert the probe just before </body>.
awk -v probe="$probe" '/<\/body>/ { print probe } { print }' "$report" > "$copy"
grep -q REPORT-CHECK "$copy" || { echo "report-check: $report has no </body>" >&2; exit 1; }

"$browser" --headless --no-sandbox --disable-gpu --window-size=1280,900 \
    --virtual-time-budget=5000 --dump-dom "file://$copy" > "$work/dom.html" 2> "$work/stderr" || {
    echo "report-check: chromium failed:" >&2; tail -5 "$work/stderr" >&2; exit 1; }

line=$(grep -o 'REPORT-CHECK svg=[0-9]* visible=[0-9]* scrollWidth=[0-9]*' "$work/dom.html" | tail -1 || true)
[ -n "$line" ] || { echo "report-check: the probe did not run (no REPORT-CHECK line in the DOM)" >&2; exit 1; }
svg=$(sed 's/.*svg=\([0-9]*\).*/\1/' <<<"$line")
visible=$(sed 's/.*visible=\([0-9]*\).*/\1/' <<<"$line")
scroll=$(sed 's/.*scrollWidth=\([0-9]*\).*/\1/' <<<"$line")
echo "report-check: $report: $svg svg, $visible visible, scrollWidth $scroll px at a 1280 px window"
if [ "$svg" -eq 0 ] || [ "$visible" -ne "$svg" ] || [ "$scroll" -gt 1280 ]; then
    echo "report-check: FAILED (every svg must be visible and scrollWidth <= 1280)" >&2
    exit 1
fi
