/* Second translation unit including the header twice; main() checks the version macros
 * against the library's run-time version. */
#include <stdio.h>
#include <string.h>

#include "fricont.h"
#include "fricont.h"

int header_a_uses_types(void);

int main(void) {
    char expect[64];
    snprintf(expect, sizeof expect, "%d.%d.%d", FRICONT_VERSION_MAJOR, FRICONT_VERSION_MINOR,
             FRICONT_VERSION_PATCH);
    int ok = strcmp(expect, fricont_version()) == 0;
    ok = ok && header_a_uses_types() == 1 + 1 + 1;
    ok = ok && strcmp(fricont_status_str(FRICONT_ERR_NULL), "FRICONT_ERR_NULL: a required pointer argument is NULL") == 0;
    printf("header (%s): %s header %s, library %s\n", __STDC_VERSION__ >= 199901L ? "C99" : "C",
           ok ? "ok:" : "MISMATCH:", expect, fricont_version());
    printf("header: %d passed, %d failed\n", ok, !ok);
    return ok ? 0 : 1;
}
