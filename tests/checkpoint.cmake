# Checkpoint and resume end to end (docs/checkpoint.md), label `checkpoint`: a bake killed with
# SIGKILL and resumed equals an uninterrupted one. Included by CMakeLists.txt in the test block.
find_program(TREEANIM_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT TREEANIM_PYTHON)
  find_program(TREEANIM_PYTHON python3 REQUIRED)
endif()
add_test(NAME checkpoint.kill_resume
  COMMAND ${TREEANIM_PYTHON} ${CMAKE_SOURCE_DIR}/tests/checkpoint/kill_resume.py $<TARGET_FILE:treeanim>)
set_tests_properties(checkpoint.kill_resume PROPERTIES LABELS checkpoint TIMEOUT 300)
