# Warnings as errors apply to the project's own targets only (linked through uh_project_options),
# never to third-party headers, which are included as SYSTEM by their imported targets.
add_library(uh_project_options INTERFACE)
target_compile_options(uh_project_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wold-style-cast -Wcast-align
  -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2 -Werror)

if(UH_SANITIZE)
  message(STATUS "UnrealHaptics: sanitizers ${UH_SANITIZE}")
  add_compile_options(-fsanitize=${UH_SANITIZE} -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=${UH_SANITIZE})
endif()

# Adds the project warnings to a target without exporting them to consumers of the installed package.
function(uh_target_warnings target)
  target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:uh_project_options>)
endfunction()

# Boost.Asio/Beast's own code trips the optimizer's flow warnings once inlined into ours (null
# dereference, mismatched new/delete, maybe-uninitialized on its optionals): the files that
# instantiate Asio's coroutines take these exceptions. gcc only knows -Wmaybe-uninitialized, and
# clang refuses an unknown warning option under -Werror, so the list follows the compiler.
set(UH_ASIO_WARNING_EXCEPTIONS -Wno-null-dereference -Wno-mismatched-new-delete)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  list(APPEND UH_ASIO_WARNING_EXCEPTIONS -Wno-maybe-uninitialized)
endif()
