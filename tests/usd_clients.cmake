# USD layers (docs/outputs.md "USD layer") read by two independent readers from npm, in Node: three.js's
# USDLoader and TinyUSDZ's wasm parser (tests/clients/usd, installed by `scripts/setup test`).
# Labels "usd;clients". The golden tree is baked once into HDF5 and both USD forms, frames 2 to 11
# (time codes from 2), again every third frame (skinned with 5 joints), and a forest of three
# turned trees with a layer each and forest.usda.
set(usd_bake_dir ${CMAKE_BINARY_DIR}/usd_clients)
set(usd_clients ${CMAKE_SOURCE_DIR}/tests/clients/usd)
set(usd_outputs "[{\"format\":\"hdf5\",\"path\":\"tree.h5\"},{\"format\":\"usd\",\"path\":\"tree.usda\",\"normals\":true},\
{\"format\":\"usd\",\"path\":\"skinned.usda\",\"skinned\":true},{\"format\":\"hdf5\",\"path\":\"step3.h5\",\"frame_step\":3},\
{\"format\":\"usd\",\"path\":\"step3.usda\",\"frame_step\":3},{\"format\":\"usd\",\"path\":\"step3-skinned.usda\",\"frame_step\":3,\"skinned\":true,\"max_joints\":5}]")
find_program(TREEANIM_SYSTEM_PYTHON python3 PATHS /usr/bin NO_DEFAULT_PATH)
add_test(NAME usd_clients_bake
         COMMAND sh -c "rm -rf '${usd_bake_dir}' && '$<TARGET_FILE:treeanim>' run '${CMAKE_SOURCE_DIR}/tests/golden/small_tree.json' -o '${usd_bake_dir}' --quiet --frames 2:11 --set 'outputs=${usd_outputs}' && '$<TARGET_FILE:treeanim>' run '${CMAKE_SOURCE_DIR}/tests/clients/scenes/forest_usd.json' -o '${usd_bake_dir}/forest' --quiet && '${TREEANIM_SYSTEM_PYTHON}' '${usd_clients}/export_frames.py' '${usd_bake_dir}/step3.h5' '${usd_bake_dir}/step3' && exec '${TREEANIM_SYSTEM_PYTHON}' '${usd_clients}/export_frames.py' '${usd_bake_dir}/tree.h5' '${usd_bake_dir}/frames'"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(usd_clients_bake PROPERTIES LABELS "usd;clients" FIXTURES_SETUP usd_bake TIMEOUT 120)

find_program(TREEANIM_USD_NODE node)  # not TREEANIM_NODE, which io_clients.cmake clears without the validator
# A Node that guesses a module's syntax (20.19 and newer) would hide a module Node 18 reads as
# CommonJS: where it can, the readers run with the guess off, as bookworm's Node 18 runs them.
set(usd_node_options "")
if(TREEANIM_USD_NODE)
  execute_process(COMMAND ${TREEANIM_USD_NODE} --no-experimental-detect-module -e 0 RESULT_VARIABLE no_detect
                  OUTPUT_QUIET ERROR_QUIET)
  if(no_detect EQUAL 0)
    set(usd_node_options --no-experimental-detect-module)
  endif()
endif()
foreach(reader three tinyusdz)
  if(TREEANIM_USD_NODE AND EXISTS ${usd_clients}/node_modules/${reader})
    add_test(NAME usd_clients_${reader}
             COMMAND sh -c "'${TREEANIM_USD_NODE}' ${usd_node_options} '${usd_clients}/check_usd_${reader}.mjs' --bake '${usd_bake_dir}/frames' --points '${usd_bake_dir}/tree.usda' --skinned '${usd_bake_dir}/skinned.usda' --forest '${usd_bake_dir}/forest' && exec '${TREEANIM_USD_NODE}' ${usd_node_options} '${usd_clients}/check_usd_${reader}.mjs' --bake '${usd_bake_dir}/step3' --points '${usd_bake_dir}/step3.usda' --skinned '${usd_bake_dir}/step3-skinned.usda'"
             WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
  else()  # a missing reader fails with the reason instead of silently passing
    add_test(NAME usd_clients_${reader}
             COMMAND sh -c "echo 'usd_clients_${reader}: node or tests/clients/usd/node_modules/${reader} missing (run scripts/setup test)'; exit 1")
  endif()
  set_tests_properties(usd_clients_${reader} PROPERTIES LABELS "usd;clients" FIXTURES_REQUIRED usd_bake TIMEOUT 300)
endforeach()

# The farm's gather writes the same forest.usda as `run`: the forest baked as three shards, then gathered.
set(usd_farm_dir ${usd_bake_dir}/forest-farm)
set(usd_forest_scene ${CMAKE_SOURCE_DIR}/tests/clients/scenes/forest_usd.json)
add_test(NAME usd_forest_gather
         COMMAND sh -c "rm -rf '${usd_farm_dir}' && for shard in 0/3 1/3 2/3; do '$<TARGET_FILE:treeanim>' run '${usd_forest_scene}' -o '${usd_farm_dir}' --quiet --shard $shard || exit 1; done; test ! -e '${usd_farm_dir}/forest.usda' && '$<TARGET_FILE:treeanim>' farm gather '${usd_forest_scene}' -o '${usd_farm_dir}' && cmp '${usd_farm_dir}/forest.usda' '${usd_bake_dir}/forest/forest.usda'"
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(usd_forest_gather PROPERTIES LABELS "usd;clients" FIXTURES_REQUIRED usd_bake TIMEOUT 120)
