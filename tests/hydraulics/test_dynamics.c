#include "check.h"
int main(int argc, char** argv) { (void)argv; CHECK(argc >= 0, "x"); TEST_MAIN_END(); }
