# Forests end to end (docs/farm.md), label `forest`: shards equal one process, a killed shard
# resumes, farm plan balances, farm submit against a fake sbatch, a folder in a later tree's way is
# refused before the first tree, a tree whose seed fails its grammar too, and outputs where a tree's
# checkpoints or the parts go. Included by CMakeLists.txt.
find_program(TREEANIM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT TREEANIM_PYTHON)
  find_program(TREEANIM_PYTHON python3 REQUIRED)
endif()
foreach(forest_case shards resume plan submit targets locked seeded checkpoint-folders)
  add_test(NAME forest.${forest_case}
    COMMAND ${TREEANIM_PYTHON} ${CMAKE_SOURCE_DIR}/tests/forest/forest_bake.py $<TARGET_FILE:treeanim> ${forest_case})
  set_tests_properties(forest.${forest_case} PROPERTIES LABELS forest TIMEOUT 300)
endforeach()
