#include <cstdio>
#include <cstring>
#include <string>

#include "fricont.h"
#include "fricont.h"

int header_cpp_a(void);

int main() {
    std::string expect = std::to_string(FRICONT_VERSION_MAJOR) + "." +
                         std::to_string(FRICONT_VERSION_MINOR) + "." +
                         std::to_string(FRICONT_VERSION_PATCH);
    bool ok = expect == fricont_version() && header_cpp_a() == 3;
    fricont_problem *p = nullptr;
    ok = ok && fricont_problem_new(nullptr, 0, nullptr, nullptr, &p) == FRICONT_ERR_NULL && p == nullptr;
    std::printf("header (C++17): %d passed, %d failed\n", ok ? 1 : 0, ok ? 0 : 1);
    return ok ? 0 : 1;
}
