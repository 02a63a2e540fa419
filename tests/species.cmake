# The species library (docs/species.md), label `species`: per species its shape, 240 frames of
# gusts at its smallest and largest height with two seeds (bounded, converged against 64
# substeps), its sway frequency in the field band (tests/species/check_species.py), and its preview
# page in the browser with its bark and leaf colours and its leaf share; the `species` command
# and a bad name. Included by CMakeLists.txt inside TREEANIM_TESTS.
set(species_table ${CMAKE_SOURCE_DIR}/grammars/species/species.json)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${species_table})
file(READ ${species_table} species_json)
string(JSON species_count LENGTH ${species_json} species)
math(EXPR species_last "${species_count} - 1")
set(species_check ${CMAKE_SOURCE_DIR}/tests/species/check_species.py)
set(species_pages ${CMAKE_BINARY_DIR}/species_pages)
find_program(TREEANIM_NODE node)

add_test(NAME species.list COMMAND /usr/bin/python3 ${species_check} --treeanim $<TARGET_FILE:treeanim> --list
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(species.list PROPERTIES LABELS species TIMEOUT 120)

# "R,G,B" of a species' colour (KEY: bark_color or leaf_color).
function(species_color i key out)
  set(rgb "")
  foreach(k 0 1 2)
    string(JSON c GET ${species_json} species ${i} tree ${key} ${k})
    list(APPEND rgb ${c})
  endforeach()
  string(REPLACE ";" "," rgb "${rgb}")
  set(${out} ${rgb} PARENT_SCOPE)
endfunction()

foreach(i RANGE ${species_last})
  string(JSON name GET ${species_json} species ${i} name)
  add_test(NAME species.${name}
           COMMAND /usr/bin/python3 ${species_check} --treeanim $<TARGET_FILE:treeanim> ${name}
           WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  set_tests_properties(species.${name} PROPERTIES LABELS species TIMEOUT 600 COST 40)  # COST: tests/stress.cmake

  species_color(${i} bark_color bark)
  species_color(${i} leaf_color leaf)
  string(JSON share GET ${species_json} species ${i} checks leaf_share)
  set(page ${species_pages}/${name})
  if(TREEANIM_NODE AND EXISTS ${CMAKE_SOURCE_DIR}/tests/clients/node/node_modules/playwright-core AND EXISTS /usr/bin/chromium)
    add_test(NAME species.preview_${name}
      COMMAND sh -c "rm -rf '${page}' && '$<TARGET_FILE:treeanim>' run configs/demo.json -o '${page}' --quiet \
--set lsystem=null --set tree=null --set 'species=\"${name}\"' --set time.frames=72 \
--set 'outputs=[{\"format\":\"html\",\"path\":\"page.html\"}]' && \
exec '${TREEANIM_NODE}' tests/clients/node/preview_page.js check '${page}/page.html' --bark ${bark} --leaf ${leaf} \
--min-leaf-share ${share}"
      WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  else()
    add_test(NAME species.preview_${name}
             COMMAND sh -c "echo 'node, chromium or playwright-core not installed (run scripts/setup test)'; exit 1")
  endif()
  set_tests_properties(species.preview_${name} PROPERTIES LABELS "species;preview" TIMEOUT 300 COST 20)
endforeach()

# configs/forest-species.json seen whole: a wood of nine species, its leaves (needle sprays and
# fronds) still reading at that distance against the oaks' colours of bark and leaf.
set(species_forest ${species_pages}/forest-species)
species_color(0 bark_color bark)
species_color(0 leaf_color leaf)
if(TREEANIM_NODE AND EXISTS ${CMAKE_SOURCE_DIR}/tests/clients/node/node_modules/playwright-core AND EXISTS /usr/bin/chromium)
  add_test(NAME species.forest_page
    COMMAND sh -c "rm -rf '${species_forest}' && '$<TARGET_FILE:treeanim>' run configs/forest-species.json \
-o '${species_forest}' --quiet --set time.frames=24 && \
exec '${TREEANIM_NODE}' tests/clients/node/preview_page.js leaves '${species_forest}/forest.html' --bark ${bark} \
--leaf ${leaf} --min-leaf-share 0.4"
    WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
else()
  add_test(NAME species.forest_page
           COMMAND sh -c "echo 'node, chromium or playwright-core not installed (run scripts/setup test)'; exit 1")
endif()
set_tests_properties(species.forest_page PROPERTIES LABELS "species;preview" TIMEOUT 300)
