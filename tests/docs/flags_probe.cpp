// Compiled only so that the build checks that the snippets' flags (CMakeLists.txt) are whole: the
// headers a consumer of the installed libraries includes are found with them.
#include <rsg/dds/views.hpp>
#include <rsg/gateway/embedded_gateway.hpp>
#include <rsg/wire/eigen.hpp>
