// tinyobjloader's implementation, compiled into the fuzz target (with the
// same TINYOBJLOADER_USE_DOUBLE as the library build) so that coverage and
// the sanitizers see inside it: the Debian shared library has neither.
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>
