// `gins export`: a run's output, or any trajectory or truth gins reads, in the formats other tools open
// (docs/formats.md §5.7). The conversions are in the library (core/io/geo_export.h, geo_formats.h); this is
// the command line around them, and what a run folder adds: its outages and rejected fixes as map markers.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

namespace gins {

struct ExportRequest {
  std::string format;  // kml | gpx | geojson | nmea | lla | tum
  std::string input;   // a run folder or a file
  std::string out_path;
  std::string stream;      // in a run folder: which output ("" = the smoother's, else the first there is)
  std::string origin;      // "lat,lon,height" for a foreign TUM file
  std::string frame;       // tum: write in this run's (folder or output file) frame
  std::string time_scale = "gps";
  double rate_hz = 1.0;    // nmea
};

CLI::App* AddExportCommand(CLI::App& app, ExportRequest* req);

// Writes req.out_path (complete or absent); prints what was written on stdout. Returns 0, or 1 with one line
// on stderr ("gins: error: ...").
int RunExport(const ExportRequest& req);

}  // namespace gins
