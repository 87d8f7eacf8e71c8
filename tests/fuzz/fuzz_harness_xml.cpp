// libFuzzer entry point: the harness XML reader, in memory (parse_harness_xml). A harness
// it accepts must survive its own round trip, as harness_xml.hpp promises: written back and
// read again it gives the same model, so the second text equals the first.
#include "fuzz_support.hpp"

#include "core/io/harness_xml.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  loom::fuzz::expect_only_input_errors([&] {
    const loom::Harness h = loom::parse_harness_xml(text, "fuzz.xml");
    const std::string written = loom::harness_to_xml(h);
    loom::Harness again;
    try {
      again = loom::parse_harness_xml(written, "written.xml");
    } catch (const loom::InputError& e) {
      loom::fuzz::finding(std::string("a harness read from the input is written as XML the reader refuses: ") +
                          e.what() + "\n--- written ---\n" + written);
    }
    const std::string rewritten = loom::harness_to_xml(again);
    if (rewritten != written)
      loom::fuzz::finding("harness XML round trip changes the model\n--- written ---\n" + written +
                          "\n--- read back and written again ---\n" + rewritten);
  });
  return 0;
}
