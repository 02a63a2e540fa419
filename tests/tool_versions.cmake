# The oldest tools the suite supports (scripts/minimum-versions, Debian bookworm's): every package
# the npm lock files pin must admit that Node.js, so that a lock updated on a machine with a
# newer Node cannot break the suite on bookworm's. Label "clients".
file(STRINGS ${CMAKE_SOURCE_DIR}/scripts/minimum-versions oldest_node REGEX "^node ")
string(REPLACE "node " "" oldest_node "${oldest_node}")
find_program(TREEANIM_ENGINES_NODE node)
set(npm_lock_files ${CMAKE_SOURCE_DIR}/src/formats/preview/package-lock.json
    ${CMAKE_SOURCE_DIR}/tests/clients/node/package-lock.json ${CMAKE_SOURCE_DIR}/tests/clients/usd/package-lock.json)
if(TREEANIM_ENGINES_NODE AND EXISTS ${CMAKE_SOURCE_DIR}/tests/clients/node/node_modules/semver)
  add_test(NAME npm.engines COMMAND ${TREEANIM_ENGINES_NODE} ${CMAKE_SOURCE_DIR}/tests/clients/node/check_engines.js
           ${oldest_node} ${npm_lock_files})
else()
  add_test(NAME npm.engines COMMAND sh -c "echo 'npm.engines: node or tests/clients/node/node_modules/semver missing (run scripts/setup test)'; exit 1")
endif()
set_tests_properties(npm.engines PROPERTIES LABELS clients TIMEOUT 60)
