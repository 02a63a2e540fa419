# The html output's page in a real browser (docs/outputs.md "Preview page"), label `preview`:
# pages baked by the CLI, each opened in Debian's chromium (headless, SwiftShader GL) by
# tests/clients/node/preview_page.js (playwright-core) at two times, which checks the view is
# drawn, moves, and shows bark and leaves in the page's colours; a forest's forest.html
# (tests/clients/scenes/forest_preview.json) shows every tree, each drawn alone where the
# forest places it, and is the same page when gathered after a sharded bake, or thinned to fit.
# Included by CMakeLists.txt
# inside TREEANIM_TESTS; chromium and playwright-core come from `scripts/setup test`.
set(preview_out ${CMAKE_BINARY_DIR}/preview_pages)
set(preview_page_only "outputs=[{\"format\":\"html\",\"path\":\"page.html\"}]")
set(preview_forest_pages "outputs=[{\"format\":\"html\",\"path\":\"trees/{tree}.html\"}]")
set(preview_small_reduced "outputs=[{\"format\":\"html\",\"path\":\"page.html\",\"max_mib\":2}]")
# The golden tree's leaves, larger and kept on: enough leaf pixels to check their colour.
set(preview_small_leaves "--set tree.leaf.size=0.3 --set hsm.leaf_detach_force=0")
# Every page in the scene colours (tree.bark_color, tree.leaf_color) the check looks for.
set(preview_colors --bark 0.36,0.26,0.18 --leaf 0.30,0.52,0.16)
set(preview_scene_colors "--set tree.bark_color=[0.36,0.26,0.18] --set tree.leaf_color=[0.30,0.52,0.16]")
add_test(NAME preview.bake
  COMMAND sh -c "rm -rf '${preview_out}' && t='$<TARGET_FILE:treeanim>' && \
\"$t\" run tests/golden/small_tree.json -o '${preview_out}/small' --quiet ${preview_scene_colors} ${preview_small_leaves} --set '${preview_page_only}' && \
\"$t\" run tests/golden/small_tree.json -o '${preview_out}/reduced' --quiet ${preview_scene_colors} ${preview_small_leaves} --set time.frames=1200 --set '${preview_small_reduced}' && \
\"$t\" run tests/clients/scenes/forest_preview.json -o '${preview_out}/forest' --quiet && \
\"$t\" run configs/forest-demo.json -o '${preview_out}/forest-demo' --quiet ${preview_scene_colors} --set time.frames=12 --set '${preview_forest_pages}' && \
\"$t\" run configs/demo.json -o '${preview_out}/demo' --quiet ${preview_scene_colors} --set time.frames=96 --set '${preview_page_only}' && \
exec \"$t\" run configs/conifer.json -o '${preview_out}/conifer' --quiet ${preview_scene_colors} --set time.frames=72 --set '${preview_page_only}'"
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(preview.bake PROPERTIES LABELS preview FIXTURES_SETUP preview_pages TIMEOUT 300 COST 100)

find_program(TREEANIM_NODE node)
set(preview_client ${CMAKE_SOURCE_DIR}/tests/clients/node/preview_page.js)
# preview_page.js COMMAND on a page of preview.bake's (a path under its folder) or any other (an absolute path).
function(preview_client_test name command page)
  if(NOT IS_ABSOLUTE ${page})
    set(page ${preview_out}/${page})
  endif()
  if(TREEANIM_NODE AND EXISTS ${CMAKE_SOURCE_DIR}/tests/clients/node/node_modules/playwright-core AND EXISTS /usr/bin/chromium)
    add_test(NAME preview.${name} COMMAND ${TREEANIM_NODE} ${preview_client} ${command} ${page} ${ARGN})
  else()
    add_test(NAME preview.${name}
             COMMAND sh -c "echo 'preview.${name}: node, chromium or playwright-core not installed (run scripts/setup test)'; exit 1")
  endif()
  # COST (tests/stress.cmake): a page in software GL takes some 20-50 s; started early.
  set_tests_properties(preview.${name} PROPERTIES LABELS preview FIXTURES_REQUIRED preview_pages TIMEOUT 300
                       WORKING_DIRECTORY ${CMAKE_SOURCE_DIR} COST 30)
endfunction()
function(preview_page_test name page)
  preview_client_test(${name} check ${page} ${preview_colors} ${ARGN})
endfunction()
preview_page_test(small small/page.html)
preview_page_test(reduced reduced/page.html --reduced yes)
preview_page_test(demo demo/page.html --min-leaf-share 0.3)
preview_page_test(conifer conifer/page.html --min-leaf-share 0.3)
preview_page_test(forest forest/forest.html --trees 3)
# configs/forest-demo.json seen whole (16 trees over 30 m x 20 m, leaves of 14 cm a few pixels
# each): its leaves still read, the wind arrow stays inside the view in a square, a tall and a
# wide window, and no plot's legend covers its title.
preview_client_test(forest_demo_leaves leaves forest-demo/forest.html ${preview_colors} --min-leaf-share 0.25)
preview_client_test(forest_demo_arrow arrow forest-demo/forest.html)
preview_client_test(forest_demo_captions captions forest-demo/forest.html)

# The farm's gather writes the same forest.html as `run`: the forest baked as three shards, then gathered.
set(preview_forest_scene ${CMAKE_SOURCE_DIR}/tests/clients/scenes/forest_preview.json)
add_test(NAME preview.forest_gather
  COMMAND sh -c "d='${preview_out}/forest-farm' && t='$<TARGET_FILE:treeanim>' && rm -rf \"$d\" && \
for shard in 0/3 1/3 2/3; do \"$t\" run '${preview_forest_scene}' -o \"$d\" --quiet --shard $shard || exit 1; done; \
test ! -e \"$d/forest.html\" && \"$t\" farm gather '${preview_forest_scene}' -o \"$d\" && cmp \"$d/forest.html\" '${preview_out}/forest/forest.html'")
set_tests_properties(preview.forest_gather PROPERTIES LABELS preview FIXTURES_REQUIRED preview_pages TIMEOUT 120)

# Pages at their size limit (tests/clients/preview_sweep.sh): the golden tree over 2 to 1,000
# frames, the demo and the paper's two largest trees under limits near what each needs; every
# page at most its max_mib; table1-38772's under 4 MiB opened in the browser.
set(preview_sweep_out ${CMAKE_BINARY_DIR}/preview_sweep)
separate_arguments(preview_sweep_colors UNIX_COMMAND "${preview_scene_colors}")
add_test(NAME preview.sweep
  COMMAND sh tests/clients/preview_sweep.sh $<TARGET_FILE:treeanim> ${preview_sweep_out} ${preview_sweep_colors}
  WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(preview.sweep PROPERTIES LABELS preview FIXTURES_SETUP preview_sweep_pages TIMEOUT 600)
preview_page_test(sweep_table1_38772 ${preview_sweep_out}/table1-38772-24/p4.html --reduced yes)
set_tests_properties(preview.sweep_table1_38772 PROPERTIES FIXTURES_REQUIRED preview_sweep_pages)

# preview.NAME: the preview forest baked into DIR under max_mib 2 with one more `--set SET`; the
# bake must succeed and forest.html fit 2 MiB and say NOTE (a grep pattern).
function(preview_forest_fit_test name dir set note)
  add_test(NAME preview.${name}
    COMMAND sh -c "d='${dir}' && rm -rf \"$d\" && \
'$<TARGET_FILE:treeanim>' run '${preview_forest_scene}' -o \"$d\" --quiet --set ${set} \
  --set 'outputs=[{\"format\":\"html\",\"path\":\"trees/{tree}.html\",\"max_mib\":2}]' && \
test $(wc -c < \"$d/forest.html\") -le 2097152 && grep -o '${note}' \"$d/forest.html\""
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(preview.${name} PROPERTIES LABELS preview TIMEOUT 300)
endfunction()

# A forest whose pages together pass max_mib: forest.html thins every tree's frames alike and says so.
preview_forest_fit_test(forest_thinned ${preview_out}/forest-thinned time.frames=600
  "Reduced to fit 2 MiB: 1 frame in [0-9]* of the trees. pages kept, the others interpolated. 3 of 3 tree pages were reduced")

# A forest whose trees do not all fit forest.html even with two frames each (broadleaves of 9,293
# vertices under 2 MiB): the bake succeeds, the page shows the first two trees and says so.
set(preview_left_out ${CMAKE_BINARY_DIR}/preview_forest_left_out)
preview_forest_fit_test(forest_left_out ${preview_left_out} lsystem.iterations=8
  "Reduced to fit 2 MiB: the first 2 of 3 trees shown, the others left out")
set_tests_properties(preview.forest_left_out PROPERTIES FIXTURES_SETUP preview_forest_left_out)
preview_page_test(forest_left_out_page ${preview_left_out}/forest.html --trees 2)
# Two trees of 9,293 vertices, each drawn alone: slower than the other pages in software GL.
set_tests_properties(preview.forest_left_out_page PROPERTIES FIXTURES_REQUIRED preview_forest_left_out TIMEOUT 600)
