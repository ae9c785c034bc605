/* lmgi_version: the header's LMGI_VERSION frozen into the library when it is built, so that a program can
 * tell the liblmgi.so it runs on from the lmgi.h it was compiled against. */
#include <lmgi.h>

_Static_assert(LMGI_VERSION_MINOR < 100 && LMGI_VERSION_PATCH < 100, "LMGI_VERSION packs each in two digits");

int lmgi_version(void)
{
    return LMGI_VERSION;
}
