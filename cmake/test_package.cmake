# ctest script: install nsp from the build tree into a scratch prefix, then build and run the
# consumer project against it with find_package, and again with add_subdirectory. Both builds
# compile and run the code snippets of README.md and docs/integration.md (cmake/consumer/
# CMakeLists.txt): the installed build is given their paths in the source tree (nothing of them
# is installed), the subdirectory build finds them in NSP_SOURCE_DIR. Last, the
# example host renderer examples/host against the installed package, and its --compare check.
# Both builds also build and run consumer_volumes (cmake/consumer/volume_files.cpp: a .vol, .nvdb
# files with each codec and a .vdb read back through nsp::nanovdb / nsp::openvdb), and the
# package's components are checked where they cannot be found: a required one fails find_package
# with a message naming the Debian package, an optional one is left out.
# Inputs: NSP_SOURCE_DIR, NSP_BINARY_DIR, WORK_DIR, GENERATOR; optional NSP_README (default
# ${NSP_SOURCE_DIR}/README.md), NSP_INTEGRATION_DOC (default ${NSP_SOURCE_DIR}/docs/integration.md)
# and NSP_EXPECT_NANOVDB / _OPENVDB / _ZIP / _BLOSC (ON when nsp's
# build found them: the consumer then requires them; the top-level CMakeLists.txt passes them).
foreach(v NSP_SOURCE_DIR NSP_BINARY_DIR WORK_DIR)
    if(NOT DEFINED ${v})
        message(FATAL_ERROR "test_package.cmake needs -D${v}=...")
    endif()
endforeach()
if(NOT DEFINED NSP_README)
    set(NSP_README ${NSP_SOURCE_DIR}/README.md)
endif()
if(NOT DEFINED NSP_INTEGRATION_DOC)
    set(NSP_INTEGRATION_DOC ${NSP_SOURCE_DIR}/docs/integration.md)
endif()
file(REMOVE_RECURSE ${WORK_DIR})

function(run)
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}")
    endif()
    message(STATUS "${out}")
endfunction()

set(expect "")
foreach(what NANOVDB OPENVDB ZIP BLOSC)
    list(APPEND expect -DNSP_EXPECT_${what}=${NSP_EXPECT_${what}})
endforeach()

run(${CMAKE_COMMAND} --install ${NSP_BINARY_DIR} --prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} -S ${NSP_SOURCE_DIR}/cmake/consumer -B ${WORK_DIR}/installed -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DNSP_README=${NSP_README}
    -DNSP_INTEGRATION_DOC=${NSP_INTEGRATION_DOC} ${expect})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/installed)
run(${WORK_DIR}/installed/consumer)
if(NSP_EXPECT_NANOVDB)
    run(${WORK_DIR}/installed/consumer_volumes)
endif()

run(${CMAKE_COMMAND} -S ${NSP_SOURCE_DIR}/cmake/consumer -B ${WORK_DIR}/subdir -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DNSP_SOURCE_DIR=${NSP_SOURCE_DIR} ${expect})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/subdir)
run(${WORK_DIR}/subdir/consumer)
if(NSP_EXPECT_NANOVDB)
    run(${WORK_DIR}/subdir/consumer_volumes)
endif()

# The components where NanoVDB's headers cannot be found (CMAKE_IGNORE_PATH hides /usr/include from
# find_path): required, find_package fails and says which Debian package to install; optional,
# nsp::nsp is found and nsp::nanovdb left out; a component nsp does not have is named. Configure
# only: a project of a few lines written here.
file(WRITE ${WORK_DIR}/components/CMakeLists.txt [=[
cmake_minimum_required(VERSION 3.20)
project(nsp_components LANGUAGES CXX)
separate_arguments(args UNIX_COMMAND "${NSP_FIND_ARGS}")
find_package(nsp 0.1 CONFIG ${args})
message(STATUS "components: nsp_FOUND=${nsp_FOUND}")
if(TARGET nsp::nanovdb)
    message(STATUS "components: nsp::nanovdb is defined")
endif()
]=])
function(configure_components name must_succeed)
    set(dir ${WORK_DIR}/components/${name})
    execute_process(COMMAND ${CMAKE_COMMAND} -S ${WORK_DIR}/components -B ${dir} -G ${GENERATOR}
        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_IGNORE_PATH=/usr/include ${ARGN}
        RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
    string(REGEX REPLACE "[ \t\r\n]+" " " out "${out}")  # CMake wraps the message's lines
    set(out "${out}" PARENT_SCOPE)
    if(must_succeed AND NOT rc EQUAL 0)
        message(FATAL_ERROR "components '${name}': configure failed (${rc}):\n${out}")
    elseif(NOT must_succeed AND rc EQUAL 0)
        message(FATAL_ERROR "components '${name}': configure should have failed:\n${out}")
    endif()
endfunction()
if(EXISTS /usr/include/nanovdb/NanoVDB.h AND NOT EXISTS /usr/local/include/nanovdb/NanoVDB.h)
    configure_components(required FALSE "-DNSP_FIND_ARGS=REQUIRED COMPONENTS nanovdb")
    if(NOT out MATCHES "Component nanovdb .*needs NanoVDB's headers.*Debian: libnanovdb-dev")
        message(FATAL_ERROR "components: a required nanovdb that is not found should fail with the Debian package's name; got:\n${out}")
    endif()
    configure_components(optional TRUE "-DNSP_FIND_ARGS=OPTIONAL_COMPONENTS nanovdb openvdb")
    if(NOT out MATCHES "nsp_FOUND=(1|TRUE|ON)" OR out MATCHES "nsp::nanovdb is defined")
        message(FATAL_ERROR "components: an optional nanovdb that is not found should leave nsp found, without nsp::nanovdb; got:\n${out}")
    endif()
endif()
configure_components(unknown FALSE "-DNSP_FIND_ARGS=REQUIRED COMPONENTS openexr")
if(NOT out MATCHES "nsp has no component 'openexr' \\(it has nanovdb and openvdb\\)")
    message(FATAL_ERROR "components: an unknown component should be named; got:\n${out}")
endif()
message(STATUS "components: a missing or unknown component is reported, an optional one left out")

# The example host renderer (examples/host), built against the installed package as a user would:
# its own geometry, lights and path loop on nsp's path-vertex kernels. --compare renders a scene
# both it and nsp::PathEstimator can render and fails unless their image means agree within 5
# standard errors.
run(${CMAKE_COMMAND} -S ${NSP_SOURCE_DIR}/examples/host -B ${WORK_DIR}/host -G ${GENERATOR}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/host)
run(${WORK_DIR}/host/nsp_host --compare)
