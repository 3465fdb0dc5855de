// Throughput of the anemometer path (framing + protocol detection + parsing), per protocol.
// An instrument sends at most ~20 records/s, so this only has to show the node never limits it.
// Usage: anemometer_decode_bench [records per protocol]   (prints a table)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_args.h"
#include "sensors/anemometer_protocol.h"
#include "sensors/anemometer_stream.h"
#include "sensors/gill_windsonic.h"
#include "sensors/nmea.h"

namespace {

using clothwind::sensors::AnemometerDecoder;
using clothwind::sensors::ParseStatus;
using clothwind::sensors::RawRecord;
using clothwind::sensors::RecordFramer;

void Run(const char* name, const std::string& record, int n) {
  std::string stream;
  for (int i = 0; i < n; ++i) stream += record + "\r\n";
  const auto t0 = std::chrono::steady_clock::now();
  RecordFramer framer;
  AnemometerDecoder decoder;
  std::vector<RawRecord> records;
  records.reserve(n);
  // Feed in 64-byte reads, like a serial port delivering bursts.
  for (size_t i = 0; i < stream.size(); i += 64)
    framer.Feed(reinterpret_cast<const uint8_t*>(stream.data()) + i, std::min<size_t>(64, stream.size() - i), 0.0,
                &records);
  int ok = 0;
  for (const auto& r : records) ok += decoder.Decode(r.data).status == ParseStatus::kOk;
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%-14s %9d %9d %12.0f %10.2f\n", name, n, ok, n / s, 1e6 * s / n);
}

}  // namespace

int Main(int argc, char** argv) {
  if (clothwind::bench::HelpAsked(argc, argv, "Usage: anemometer_decode_bench [records per protocol]   (prints a table)"))
    return 0;
  const int n = clothwind::bench::OptionalCount(argc, argv, "records per protocol", 200000, 1);
  std::printf("%-14s %9s %9s %12s %10s\n", "protocol", "records", "readings", "records/s", "us/record");
  Run("nmea_mwv", "$IIMWV,229.0,R,5.8,N,A*39", n);
  Run("nmea_mwd", clothwind::sensors::WithNmeaChecksum("WIMWD,270.0,T,265.5,M,10.0,N,5.1,M"), n);
  Run("gill_polar", clothwind::sensors::FrameGillRecord("Q,229,002.74,M,00,"), n);
  Run("gill_uv", clothwind::sensors::FrameGillRecord("Q,+001.59,-002.74,M,00,"), n);
  Run("csv", "3.25,270,6.5", n);
  Run("fine_offset", "052DD200508A007E271C2A1006240100", n);
  return 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("anemometer_decode_bench", argc, argv, Main); }
