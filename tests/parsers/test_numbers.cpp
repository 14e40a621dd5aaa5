// The library's one number reader (readNumber, input_file.hpp) and parseFiniteNumber on it: what
// the tool's options, the scenario files and the URDF reader (urdfdom's form: space before) read.
#include <gtest/gtest.h>

#include <clocale>
#include <cmath>
#include <limits>
#include <string>

#include "kdl_space/parsers/input_file.hpp"

namespace kdl_space::test {
namespace {

TEST(Numbers, WhatReadsAsWhat) {
  const struct {
    std::string text;
    NumberText expected;
    double value;  // for Finite
  } cases[] = {
      {"5", NumberText::Finite, 5.0},
      {"+5", NumberText::Finite, 5.0},
      {"-2.5e-3", NumberText::Finite, -2.5e-3},
      {"5.", NumberText::Finite, 5.0},
      {".5", NumberText::Finite, 0.5},
      {"1E3", NumberText::Finite, 1000.0},
      {"0.1", NumberText::Finite, 0.1},  // correctly rounded, as strtod
      {"1e-400", NumberText::Finite, 0.0},  // below the denormals: the nearest double
      {"4e-320", NumberText::Finite, 4e-320},
      {"1e400", NumberText::TooLarge, 0.0},
      {"-1e999", NumberText::TooLarge, 0.0},
      {"nan", NumberText::NotFinite, 0.0},
      {"-inf", NumberText::NotFinite, 0.0},
      {"Infinity", NumberText::NotFinite, 0.0},
      {"NaN(123_a)", NumberText::NotFinite, 0.0},
      {"nan(1 2)", NumberText::NotANumber, 0.0},
      {"abc", NumberText::NotANumber, 0.0},
      {"", NumberText::NotANumber, 0.0},
      {" 1", NumberText::NotANumber, 0.0},
      {"1 ", NumberText::NotANumber, 0.0},
      {"1.5x", NumberText::NotANumber, 0.0},
      {"0x5", NumberText::NotANumber, 0.0},
      {"5,0", NumberText::NotANumber, 0.0},
      {"1e", NumberText::NotANumber, 0.0},
      {".", NumberText::NotANumber, 0.0},
      {"+-1", NumberText::NotANumber, 0.0},
      {".inf", NumberText::NotANumber, 0.0},  // YAML's name: the scenario reader's to know
  };
  for (const auto& c : cases) {
    double v = -7.0;
    EXPECT_EQ(readNumber(c.text, v), c.expected) << "'" << c.text << "'";
    EXPECT_EQ(v, c.expected == NumberText::Finite ? c.value : -7.0) << "'" << c.text << "': untouched unless finite";
  }
}

TEST(Numbers, SpaceBeforeOnlyWhenAsked) {
  double v = 0.0;
  EXPECT_EQ(readNumber("  5", v, true), NumberText::Finite);
  EXPECT_EQ(v, 5.0);
  EXPECT_EQ(readNumber("\t-1e999", v, true), NumberText::TooLarge);
  EXPECT_EQ(readNumber(" nan", v, true), NumberText::NotFinite);
  EXPECT_EQ(readNumber("5 ", v, true), NumberText::NotANumber);
  EXPECT_EQ(readNumber("   ", v, true), NumberText::NotANumber);
}

TEST(Numbers, TheCLocaleWhateverTheProgramsLocale) {
  // A locale with a decimal comma, when the machine has one: "1.5" still reads 1.5.
  const std::string saved = std::setlocale(LC_NUMERIC, nullptr);
  const bool comma = std::setlocale(LC_NUMERIC, "de_DE.UTF-8") != nullptr;
  double v = 0.0;
  EXPECT_EQ(readNumber("1.5", v), NumberText::Finite);
  EXPECT_EQ(v, 1.5);
  EXPECT_EQ(readNumber("1,5", v), NumberText::NotANumber);
  std::setlocale(LC_NUMERIC, saved.c_str());
  if (!comma) GTEST_SKIP() << "no de_DE.UTF-8 locale here: read in the C locale only";
}

TEST(Numbers, ParseFiniteNumberSaysWhy) {
  const struct {
    std::string text, why;
  } cases[] = {{"abc", "'abc' is not a number"},
               {"1e400", "'1e400' is too large (not a finite number)"},
               {"inf", "'inf' is not a finite number"},
               {" 1", "' 1' is not a number"}};
  for (const auto& c : cases) {
    double v = 3.0;
    std::string why;
    EXPECT_FALSE(parseFiniteNumber(c.text, v, why));
    EXPECT_EQ(why, c.why);
    EXPECT_EQ(v, 3.0);
  }
  double v = 0.0;
  std::string why;
  EXPECT_TRUE(parseFiniteNumber("-0.25", v, why));
  EXPECT_EQ(v, -0.25);
}

}  // namespace
}  // namespace kdl_space::test
