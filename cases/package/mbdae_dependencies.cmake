# The libraries mbdae links that are found by name (SUNDIALS IDA, KLU, SPQR, CHOLMOD), as
# IMPORTED targets mbdae_dep::NAME. Included by the build (CMakeLists.txt) and by the installed
# package (mbdaeConfig.cmake), so an installed mbdae::mbdae carries library names, not the paths
# of the machine it was built on. sundials_core (SUNDIALS 7; 6.4 has none) is linked when present.
include_guard(GLOBAL)

set(MBDAE_DEPENDENCIES_FOUND TRUE)
set(MBDAE_DEPENDENCIES_MISSING "")

function(mbdae_import_library target name)
  find_library(MBDAE_LIB_${name} ${name})
  if(NOT MBDAE_LIB_${name})
    if(NOT "OPTIONAL" IN_LIST ARGN)
      set(MBDAE_DEPENDENCIES_FOUND FALSE PARENT_SCOPE)
      set(MBDAE_DEPENDENCIES_MISSING "${MBDAE_DEPENDENCIES_MISSING} lib${name}" PARENT_SCOPE)
    endif()
    return()
  endif()
  if(NOT TARGET mbdae_dep::${target})
    add_library(mbdae_dep::${target} UNKNOWN IMPORTED)
    set_target_properties(mbdae_dep::${target} PROPERTIES IMPORTED_LOCATION "${MBDAE_LIB_${name}}")
  endif()
endfunction()

find_path(MBDAE_KLU_INCLUDE_DIR klu.h PATH_SUFFIXES suitesparse)
if(NOT MBDAE_KLU_INCLUDE_DIR)
  set(MBDAE_DEPENDENCIES_FOUND FALSE)
  set(MBDAE_DEPENDENCIES_MISSING "${MBDAE_DEPENDENCIES_MISSING} klu.h")
endif()
mbdae_import_library(klu klu)
mbdae_import_library(sundials_idas sundials_idas)  # IDAS: IDA with forward sensitivities (the same IDA for runs without)
mbdae_import_library(sundials_nvecserial sundials_nvecserial)
mbdae_import_library(sundials_sunmatrixsparse sundials_sunmatrixsparse)
mbdae_import_library(sundials_core sundials_core OPTIONAL)
mbdae_import_library(spqr spqr)
mbdae_import_library(cholmod cholmod)
mbdae_import_library(suitesparseconfig suitesparseconfig)
# KLU's headers (suitesparse/): the build adds them with -I (cases' includes); an installed
# mbdae::mbdae gets them through this target.
if(MBDAE_KLU_INCLUDE_DIR AND NOT TARGET mbdae_dep::klu_headers)
  add_library(mbdae_dep::klu_headers INTERFACE IMPORTED)
  set_target_properties(mbdae_dep::klu_headers PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${MBDAE_KLU_INCLUDE_DIR}")
endif()

# What mbdae_core and mbdae_formulation link (sundials_core last: the other SUNDIALS libraries
# use it).
set(MBDAE_CORE_DEPENDENCIES mbdae_dep::sundials_idas mbdae_dep::sundials_sunmatrixsparse
    mbdae_dep::sundials_nvecserial mbdae_dep::klu)
if(TARGET mbdae_dep::sundials_core)
  list(APPEND MBDAE_CORE_DEPENDENCIES mbdae_dep::sundials_core)
endif()
set(MBDAE_FORMULATION_DEPENDENCIES mbdae_dep::spqr mbdae_dep::cholmod mbdae_dep::suitesparseconfig)
