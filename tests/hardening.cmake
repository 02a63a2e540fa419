# Hardening tests, label `hardening`: the bad-input corpus, failure injection around a
# real bake, a replay of every fuzz corpus (seeds + kept reproducers) through the fuzz
# targets built with the normal compiler, and two bakes sharing two cores. Included by
# CMakeLists.txt inside the test block.
find_program(TREEANIM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)  # the one with h5py
if(NOT TREEANIM_PYTHON)
  find_program(TREEANIM_PYTHON python3 REQUIRED)
endif()

add_test(NAME hardening.bad_corpus
  COMMAND ${TREEANIM_PYTHON} ${CMAKE_SOURCE_DIR}/tests/hardening/bad_corpus.py
          $<TARGET_FILE:treeanim> ${CMAKE_SOURCE_DIR}/tests/bad)
set_tests_properties(hardening.bad_corpus PROPERTIES LABELS hardening TIMEOUT 300)

set(failure_injection ${CMAKE_SOURCE_DIR}/tests/hardening/failure_injection.py)
execute_process(COMMAND ${TREEANIM_PYTHON} ${failure_injection} - --list
  OUTPUT_VARIABLE failure_scenarios OUTPUT_STRIP_TRAILING_WHITESPACE COMMAND_ERROR_IS_FATAL ANY)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${failure_injection})
string(REPLACE "\n" ";" failure_scenarios "${failure_scenarios}")
foreach(line ${failure_scenarios})
  string(REPLACE " " ";" fields "${line}")  # "name" or "name defect"
  list(GET fields 0 scenario)
  add_test(NAME hardening.${scenario}
    COMMAND ${TREEANIM_PYTHON} ${failure_injection} $<TARGET_FILE:treeanim> ${scenario})
  set_tests_properties(hardening.${scenario} PROPERTIES LABELS hardening TIMEOUT 300
    SKIP_RETURN_CODE 77)
  if(line MATCHES " defect$")  # reproduces an open defect: see OPEN_DEFECTS in the script
    set_tests_properties(hardening.${scenario} PROPERTIES DISABLED TRUE)
  endif()
endforeach()

file(GLOB fuzz_targets CONFIGURE_DEPENDS ${CMAKE_SOURCE_DIR}/tests/fuzz/fuzz_*.cpp)
foreach(src ${fuzz_targets})
  get_filename_component(fuzz_name ${src} NAME_WE)
  add_executable(replay_${fuzz_name} ${src} ${CMAKE_SOURCE_DIR}/tests/hardening/fuzz_replay_main.cpp)
  target_link_libraries(replay_${fuzz_name} PRIVATE treeanim_core)
  add_test(NAME hardening.replay_${fuzz_name}
    COMMAND replay_${fuzz_name} ${CMAKE_SOURCE_DIR}/tests/fuzz/corpus/${fuzz_name})
  set_tests_properties(hardening.replay_${fuzz_name} PROPERTIES LABELS hardening TIMEOUT 300)
endforeach()

# Two bakes sharing two cores: each steps on the cores left to it, to the same bytes.
add_test(NAME hardening.contention
  COMMAND ${TREEANIM_PYTHON} ${CMAKE_SOURCE_DIR}/tests/hardening/contention.py
          $<TARGET_FILE:treeanim> ${CMAKE_SOURCE_DIR}/configs/demo.json)
set_tests_properties(hardening.contention PROPERTIES LABELS hardening TIMEOUT 300 SKIP_RETURN_CODE 77
  RUN_SERIAL TRUE)
