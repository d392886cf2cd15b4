#pragma once
// Where a test writes its files: build/<config>/test_output/<folder>/<suite.test>/<name>. CTest
// runs every test in a process of its own, two at a time, so each test gets a folder of its own:
// two tests writing tex.png into one folder raced (one read the other's half-written file).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

inline std::string test_output_path(const std::string& folder, const std::string& name) {
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::string own = test ? std::string(test->test_suite_name()) + "." + test->name() : "outside_tests";
    const std::filesystem::path dir = std::filesystem::path(MIPRASTER_TEST_OUTPUT_DIR) / folder / own;
    std::filesystem::create_directories(dir);
    return (dir / name).string();
}
