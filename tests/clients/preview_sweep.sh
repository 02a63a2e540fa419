#!/bin/sh
# Preview pages at their size limit, baked by the CLI (docs/outputs.md "Preview page"): trees from
# 223 to 211,864 vertices, bakes of 2 to 1,000 frames, each with pages under limits (max_mib) close
# to what the tree's page needs, so that the pages are reduced, and each page must come out at most
# its limit. Prints every page's size against its limit, the largest share last.
#   preview_sweep.sh TREEANIM OUTDIR [--set PATH=VALUE ...]   (the --set arguments go to every bake)
set -eu
treeanim=$1 out=$2
shift 2
rm -rf "$out"

# bake SCENE FRAMES MIB...: one bake of SCENE for FRAMES frames, a page per limit: OUT/NAME-FRAMES/pMIB.html
bake() {
  scene=$1 frames=$2
  shift 2
  outputs=""
  for mib in "$@"; do outputs="$outputs${outputs:+,}{\"format\":\"html\",\"path\":\"p$mib.html\",\"max_mib\":$mib}"; done
  "$treeanim" run "$scene" -o "$out/$(basename "$scene" .json)-$frames" --quiet $sets \
    --set time.frames="$frames" --set "outputs=[$outputs]"
}
sets="$*"
for frames in 2 3 17 96 400 1000; do bake tests/golden/small_tree.json "$frames" 2 3; done
bake configs/demo.json 2 2
bake configs/demo.json 24 2 3
bake configs/table1-38772.json 24 4 5
bake configs/table1-211812.json 3 16 64

largest=0
for page in "$out"/*/p*.html; do
  mib=$(basename "$page" .html | cut -c2-)
  bytes=$(wc -c < "$page")
  limit=$((mib * 1048576))
  share=$((bytes * 1000 / limit))
  echo "$page: $bytes bytes, limit $limit ($share per mille)"
  if [ "$bytes" -gt "$limit" ]; then echo "$page: above its limit" >&2; exit 1; fi
  if [ "$share" -gt "$largest" ]; then largest=$share; at="$page: $bytes of $limit bytes"; fi
done
echo "largest: $at"
