// The header as C++17, included twice in two translation units (this one and header_b.cpp).
#include "fricont.h"
#include "fricont.h"

int header_cpp_a(void);

int header_cpp_a(void) {
    fricont_event ev{};
    ev.to = FRICONT_STICK;
    fricont_status s = FRICONT_OK;
    fricont_csr m{};
    (void)m;
    return static_cast<int>(s) + ev.to + FRICONT_STORAGE_LOWER + FRICONT_END_WINDOW;
}
