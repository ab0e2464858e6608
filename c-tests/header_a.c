/* The header compiles cleanly as C99 (and as C++17: header_a.cpp includes this file),
 * included twice in this translation unit and in header_b.c. */
#include "fricont.h"
#include "fricont.h"

int header_a_uses_types(void);

int header_a_uses_types(void) {
    fricont_event ev = {0, 0, 0.0, 0, FRICONT_OPEN, FRICONT_STICK, false, false, 0.0};
    fricont_state st = {0.0, 0.0, NULL, 0, NULL, 0, NULL, 0, NULL, 0};
    fricont_status s = FRICONT_OK;
    fricont_load_fn f = NULL;
    fricont_weights_fn w = NULL;
    fricont_free_fn fr = NULL;
    (void)st;
    (void)f;
    (void)w;
    (void)fr;
    return (int)s + (int)ev.to + FRICONT_STORAGE_LOWER + FRICONT_END_WINDOW;
}
