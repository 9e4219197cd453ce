# cmake/nspVolumeFiles.cmake: what nsp's volume-file readers need, found in the current environment,
# and their interface targets: nsp/io/nanovdb.hpp (NanoVDB's headers; zlib and c-blosc for
# compressed .nvdb files) and nsp/io/openvdb.hpp (OpenVDB too). One file for both sides: the
# top-level CMakeLists.txt includes it for the build tree's targets, the installed nspConfig.cmake
# for a consumer's, so a build against the install prefix gets the same compile definitions and
# libraries as nsp's own tests.

# nsp_find_nanovdb(): looks for NanoVDB's headers and its two compression codecs. Sets, in the
# caller's scope:
#   NSP_NANOVDB_FOUND         true when nanovdb/NanoVDB.h is found (NSP_NANOVDB_INCLUDE_DIR, cached)
#   NSP_NANOVDB_DEFINITIONS   NSP_HAVE_NANOVDB=1, and NANOVDB_USE_ZIP / NANOVDB_USE_BLOSC for the
#                             codecs found (NanoVDB's IO.h reads a compressed grid only with them)
#   NSP_NANOVDB_LIBRARIES     zlib's and c-blosc's targets, for the codecs found
#   NSP_NANOVDB_CODECS        a sentence for the configure output: which codecs are on
function(nsp_find_nanovdb)
    find_path(NSP_NANOVDB_INCLUDE_DIR nanovdb/NanoVDB.h)
    set(found FALSE)
    set(definitions "")
    set(libraries "")
    if(NSP_NANOVDB_INCLUDE_DIR)
        set(found TRUE)
        set(definitions NSP_HAVE_NANOVDB=1)
        find_package(ZLIB QUIET)
        if(ZLIB_FOUND)
            list(APPEND definitions NANOVDB_USE_ZIP)
            list(APPEND libraries ZLIB::ZLIB)
            set(zip "ZIP on (zlib)")
        else()
            set(zip "ZIP off (Debian: zlib1g-dev)")
        endif()
        _nsp_find_blosc(blosc_target)
        if(blosc_target)
            list(APPEND definitions NANOVDB_USE_BLOSC)
            list(APPEND libraries ${blosc_target})
            set(blosc "Blosc on (c-blosc)")
        else()
            set(blosc "Blosc off (Debian: libblosc-dev)")
        endif()
        set(NSP_NANOVDB_CODECS "compressed .nvdb: ${zip}, ${blosc}" PARENT_SCOPE)
    endif()
    set(NSP_NANOVDB_FOUND ${found} PARENT_SCOPE)
    set(NSP_NANOVDB_DEFINITIONS ${definitions} PARENT_SCOPE)
    set(NSP_NANOVDB_LIBRARIES ${libraries} PARENT_SCOPE)
endfunction()

# c-blosc 1 installs no CMake package: OpenVDB's find module's target Blosc::blosc when it is there,
# else an imported target of nsp's own over blosc.h and libblosc. Sets `out` to the target, or to
# "" when c-blosc is not found.
function(_nsp_find_blosc out)
    if(TARGET Blosc::blosc)
        set(${out} Blosc::blosc PARENT_SCOPE)
        return()
    endif()
    if(NOT TARGET nsp::blosc)
        find_path(NSP_BLOSC_INCLUDE_DIR blosc.h)
        find_library(NSP_BLOSC_LIBRARY NAMES blosc)
        if(NOT NSP_BLOSC_INCLUDE_DIR OR NOT NSP_BLOSC_LIBRARY)
            set(${out} "" PARENT_SCOPE)
            return()
        endif()
        add_library(nsp::blosc UNKNOWN IMPORTED)
        set_target_properties(nsp::blosc PROPERTIES IMPORTED_LOCATION "${NSP_BLOSC_LIBRARY}"
                                                    INTERFACE_INCLUDE_DIRECTORIES "${NSP_BLOSC_INCLUDE_DIR}")
    endif()
    set(${out} nsp::blosc PARENT_SCOPE)
endfunction()

# nsp_find_openvdb(): looks for OpenVDB with its find module (Debian installs it off CMake's
# module path). Sets NSP_OPENVDB_FOUND, and NSP_OPENVDB_CODECS for the configure output: the
# version and the codecs libopenvdb was built with (they are compiled into it, so nsp adds nothing
# for compressed .vdb files; Debian's has Blosc and zlib).
function(nsp_find_openvdb)
    set(saved_module_path ${CMAKE_MODULE_PATH})
    list(APPEND CMAKE_MODULE_PATH /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/cmake/OpenVDB /usr/local/lib/cmake/OpenVDB)
    find_package(OpenVDB QUIET)
    set(CMAKE_MODULE_PATH ${saved_module_path})
    set(NSP_OPENVDB_FOUND ${OpenVDB_FOUND} PARENT_SCOPE)
    if(OpenVDB_FOUND)
        set(codecs "")
        if(OpenVDB_USES_BLOSC)
            list(APPEND codecs Blosc)
        endif()
        if(OpenVDB_USES_ZLIB)
            list(APPEND codecs zlib)
        endif()
        if(codecs)
            string(REPLACE ";" " and " codecs "${codecs}")
            set(codecs "libopenvdb reads .vdb files compressed with ${codecs}")
        else()
            set(codecs "libopenvdb reads uncompressed .vdb files only")
        endif()
        set(NSP_OPENVDB_CODECS "OpenVDB ${OpenVDB_VERSION} found (${codecs})" PARENT_SCOPE)
    endif()
endfunction()

# nsp_add_nanovdb_target(<name> CORE <target> [IMPORTED]): the interface target of nsp/io/nanovdb.hpp
# from what nsp_find_nanovdb found (call it first): links CORE (nsp's library target), NanoVDB's
# headers and the codecs' libraries, with NSP_NANOVDB_DEFINITIONS. IMPORTED: an imported target
# (the package config's), else a target of the build tree.
function(nsp_add_nanovdb_target name)
    cmake_parse_arguments(arg "IMPORTED" "CORE" "" ${ARGN})
    if(arg_IMPORTED)
        add_library(${name} INTERFACE IMPORTED)
    else()
        add_library(${name} INTERFACE)
    endif()
    target_include_directories(${name} SYSTEM INTERFACE ${NSP_NANOVDB_INCLUDE_DIR})
    target_compile_definitions(${name} INTERFACE ${NSP_NANOVDB_DEFINITIONS})
    target_link_libraries(${name} INTERFACE ${arg_CORE} ${NSP_NANOVDB_LIBRARIES})
endfunction()

# nsp_add_openvdb_target(<name> NANOVDB <target> [IMPORTED]): the interface target of
# nsp/io/openvdb.hpp (after nsp_find_openvdb found OpenVDB): links the NANOVDB target and
# OpenVDB::openvdb, and defines NSP_HAVE_OPENVDB=1.
function(nsp_add_openvdb_target name)
    cmake_parse_arguments(arg "IMPORTED" "NANOVDB" "" ${ARGN})
    if(arg_IMPORTED)
        add_library(${name} INTERFACE IMPORTED)
    else()
        add_library(${name} INTERFACE)
    endif()
    target_link_libraries(${name} INTERFACE ${arg_NANOVDB} OpenVDB::openvdb)
    target_compile_definitions(${name} INTERFACE NSP_HAVE_OPENVDB=1)
endfunction()
