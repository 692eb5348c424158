// How long (wall s) a rostest waits at most for something that must happen: generous, for a loaded machine or
// a slow robot. Every wait ends as soon as its condition holds, so a fast machine never pays it.
#pragma once

namespace test_wait {
constexpr double kDeadline = 60.0;
}  // namespace test_wait
