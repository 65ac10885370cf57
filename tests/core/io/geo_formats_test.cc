// The geo formats (KML, GPX, GeoJSON): the track's split at its no-fix intervals, the same features in the
// three documents, escaping, coordinate order and time stamps, checked on the written text.
#include "core/io/geo_formats.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace gins {
namespace GINS_TEST_FILE {

using Writer = void (*)(const GeoTrack&, const GeoWriteOptions&, std::FILE*);

// The whole document a writer makes, through a real FILE* as the callers use it.
std::string Render(Writer write, const GeoTrack& track, const GeoWriteOptions& options = {}) {
  std::FILE* f = std::tmpfile();
  EXPECT_NE(f, nullptr);
  if (f == nullptr) return "";
  write(track, options, f);
  std::string text;
  std::rewind(f);
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof(buf), f)) > 0;) text.append(buf, n);
  std::fclose(f);
  return text;
}

int Occurrences(const std::string& text, const std::string& needle) {
  int n = 0;
  for (size_t pos = text.find(needle); pos != std::string::npos; pos = text.find(needle, pos + needle.size())) ++n;
  return n;
}

// n samples dt apart from t0, walking north-east from (31.5°, 120.4°).
GeoTrack MakeTrack(int n, double t0 = 0.0, double dt = 1.0) {
  GeoTrack track;
  track.name = "eskf";
  for (int i = 0; i < n; ++i) {
    GeoSample s;
    s.t = t0 + i * dt;
    s.lat_deg = 31.5 + 1e-5 * i;
    s.lon_deg = 120.4 + 2e-5 * i;
    s.height_m = 12.25 + 0.5 * i;
    track.samples.push_back(s);
  }
  return track;
}

GeoFeatureCounts Counts(const GeoTrack& track) { return CountGeoFeatures(track); }

TEST(GeoFormats, SplitsTheTrackAtOutages) {
  GeoTrack track = MakeTrack(100);  // t = 0 .. 99
  EXPECT_EQ(Counts(track).lines, 1);
  EXPECT_EQ(Counts(track).points, 0);
  track.no_fix.push_back({20.0, 30.0, "outage"});
  EXPECT_EQ(Counts(track).lines, 3);  // track, outage, track
  track.no_fix.push_back({60.5, 70.5, "gap"});
  EXPECT_EQ(Counts(track).lines, 5);
  EXPECT_EQ(Counts(track).points, 0);
}

TEST(GeoFormats, IntervalsAtTheStartOrTheEndLeaveNoEmptyTrackPiece) {
  GeoTrack start = MakeTrack(50);
  start.no_fix.push_back({-5.0, 10.0, "gap"});
  EXPECT_EQ(Counts(start).lines, 2);  // gap, track
  GeoTrack end = MakeTrack(50);
  end.no_fix.push_back({40.0, 100.0, "outage"});
  EXPECT_EQ(Counts(end).lines, 2);  // track, outage
  GeoTrack both = MakeTrack(50);
  both.no_fix = {{0.0, 10.0, "gap"}, {40.0, 49.0, "outage"}};
  EXPECT_EQ(Counts(both).lines, 3);
  GeoTrack all = MakeTrack(50);
  all.no_fix.push_back({-1.0, 100.0, "outage"});
  EXPECT_EQ(Counts(all).lines, 1);
  EXPECT_NE(Render(WriteGpx, all).find("<type>outage</type>"), std::string::npos);
}

TEST(GeoFormats, AnIntervalWithoutSamplesInsideSplitsNothing) {
  GeoTrack track = MakeTrack(10);
  track.no_fix.push_back({4.2, 4.8, "gap"});  // between the samples at 4 and 5
  EXPECT_EQ(Counts(track).lines, 1);
  EXPECT_EQ(Render(WriteGpx, track).find("<type>gap</type>"), std::string::npos);
}

TEST(GeoFormats, AFirstPieceOfOneSampleJoinsTheNext) {
  GeoTrack track = MakeTrack(10);
  track.no_fix.push_back({1.0, 20.0, "outage"});  // only the sample at 0 is outside
  EXPECT_EQ(Counts(track).lines, 1);
  const std::string gpx = Render(WriteGpx, track);
  EXPECT_EQ(Occurrences(gpx, "<trkpt"), 10);  // the lone first sample is kept, in the outage's line
  EXPECT_NE(gpx.find("<gins:t_start>0.000</gins:t_start>"), std::string::npos);
}

TEST(GeoFormats, ConsecutivePiecesShareTheirBoundarySample) {
  GeoTrack track = MakeTrack(100);
  track.no_fix = {{20.0, 30.0, "outage"}, {60.0, 70.0, "gap"}};
  const GeoFeatureCounts counts = Counts(track);
  ASSERT_EQ(counts.lines, 5);
  // Each of the 4 boundaries repeats one sample.
  EXPECT_EQ(Occurrences(Render(WriteGpx, track), "<trkpt"), 100 + counts.lines - 1);
  EXPECT_EQ(Occurrences(Render(WriteKml, track), "\n120."), 100 + counts.lines - 1);  // one vertex a line

  // Each piece starts where the one before ends, in time.
  const std::string json = Render(WriteGeoJson, track);
  // Hand-parsed: std::regex trips GCC 12's -Wmaybe-uninitialized in the sanitizer build (-O1 -Werror).
  std::vector<std::string> kinds, starts, ends;
  const auto value_after = [&json](const std::string& key, size_t from, char end) {
    const size_t begin = json.find(key, from) + key.size();
    return json.substr(begin, json.find(end, begin) - begin);
  };
  for (size_t at = json.find("\"kind\": \""); at != std::string::npos; at = json.find("\"kind\": \"", at + 1)) {
    kinds.push_back(value_after("\"kind\": \"", at, '"'));
    starts.push_back(value_after("\"t_start\": ", at, ','));
    ends.push_back(value_after("\"t_end\": ", at, ','));
  }
  EXPECT_EQ(kinds, (std::vector<std::string>{"track", "outage", "track", "gap", "track"}));
  EXPECT_EQ(starts, (std::vector<std::string>{"0.000", "19.000", "30.000", "59.000", "70.000"}));
  EXPECT_EQ(ends, (std::vector<std::string>{"19.000", "30.000", "59.000", "70.000", "99.000"}));
}

TEST(GeoFormats, NamesEachLineByTrackAndKind) {
  GeoTrack track = MakeTrack(40);
  track.no_fix.push_back({10.0, 20.0, "outage"});
  const std::string kml = Render(WriteKml, track);
  EXPECT_EQ(Occurrences(kml, "<name>eskf track</name>"), 2);
  EXPECT_EQ(Occurrences(kml, "<name>eskf outage</name>"), 1);
  EXPECT_EQ(Occurrences(kml, "<styleUrl>#outage</styleUrl>"), 1);
  EXPECT_NE(kml.find("<altitudeMode>absolute</altitudeMode>"), std::string::npos);
  const std::string gpx = Render(WriteGpx, track);
  EXPECT_EQ(Occurrences(gpx, "<trk>\n<name>eskf track</name>\n<type>track</type>"), 2);
  EXPECT_EQ(Occurrences(gpx, "<trk>\n<name>eskf outage</name>\n<type>outage</type>"), 1);
  const std::string json = Render(WriteGeoJson, track);
  EXPECT_EQ(Occurrences(json, "{\"name\": \"eskf outage\", \"kind\": \"outage\", \"t_start\": 9.000"), 1);
}

TEST(GeoFormats, RejectedFixesArePointsBeforeTheTracks) {
  GeoTrack track = MakeTrack(30);
  track.no_fix.push_back({10.0, 15.0, "outage"});
  track.rejected = {{12.5, 31.6, 120.5, 30.0, "eskf"}, {20.25, 31.7, 120.6, 31.0, "smoother"}};
  const GeoFeatureCounts counts = Counts(track);
  EXPECT_EQ(counts.lines, 3);
  EXPECT_EQ(counts.points, 2);

  const std::string gpx = Render(WriteGpx, track);
  EXPECT_EQ(Occurrences(gpx, "<wpt "), 2);
  EXPECT_EQ(Occurrences(gpx, "<trk>"), 3);
  EXPECT_LT(gpx.rfind("</wpt>"), gpx.find("<trk>"));  // GPX 1.1 schema order
  EXPECT_NE(gpx.find("<wpt lat=\"31.600000000\" lon=\"120.500000000\"><ele>30.0000</ele><name>rejected fix (eskf) "
                     "t=12.500</name><type>rejected_fix</type>"),
            std::string::npos);
  EXPECT_NE(gpx.find("<gins:estimator>smoother</gins:estimator>"), std::string::npos);

  const std::string kml = Render(WriteKml, track);
  EXPECT_EQ(Occurrences(kml, "<Placemark>"), 5);
  EXPECT_EQ(Occurrences(kml, "<Point>"), 2);
  EXPECT_EQ(Occurrences(kml, "<LineString>"), 3);
  EXPECT_NE(kml.find("<name>rejected fix (smoother) t=20.250</name>"), std::string::npos);
  EXPECT_NE(kml.find("<Data name=\"estimator\"><value>eskf</value></Data>"), std::string::npos);

  const std::string json = Render(WriteGeoJson, track);
  EXPECT_EQ(Occurrences(json, "{\"type\": \"Feature\""), 5);
  EXPECT_EQ(Occurrences(json, "\"type\": \"Point\""), 2);
  EXPECT_EQ(Occurrences(json, "\"type\": \"LineString\""), 3);
  EXPECT_NE(json.find("{\"name\": \"rejected fix (eskf) t=12.500\", \"kind\": \"rejected_fix\", \"t\": 12.500, "
                      "\"estimator\": \"eskf\"}"),
            std::string::npos);
}

TEST(GeoFormats, ATrackOfOneSampleIsAPoint) {
  GeoTrack track = MakeTrack(1);
  EXPECT_EQ(Counts(track).lines, 0);
  EXPECT_EQ(Counts(track).points, 1);
  EXPECT_NE(Render(WriteGpx, track).find("<name>eskf track</name><type>track</type>"), std::string::npos);
  EXPECT_EQ(Occurrences(Render(WriteKml, track), "<Point>"), 1);
  EXPECT_NE(Render(WriteGeoJson, track).find("\"kind\": \"track\", \"t\": 0.000}, \"geometry\": {\"type\": \"Point\""),
            std::string::npos);
}

TEST(GeoFormats, AnEmptyTrackIsAnEmptyDocument) {
  const GeoTrack track = MakeTrack(0);
  EXPECT_EQ(Counts(track).lines, 0);
  EXPECT_EQ(Counts(track).points, 0);
  EXPECT_EQ(Render(WriteGeoJson, track), "{\"type\": \"FeatureCollection\", \"name\": \"eskf\", \"features\": [\n]}\n");
  EXPECT_EQ(Occurrences(Render(WriteKml, track), "<Placemark>"), 0);
  EXPECT_NE(Render(WriteGpx, track).find("</metadata>\n</gpx>\n"), std::string::npos);
}

TEST(GeoFormats, EscapesNamesInXmlAndJson) {
  GeoTrack track = MakeTrack(3);
  track.name = "a&b <c> \"d\" 'e' \\f";
  const std::string escaped_xml = "a&amp;b &lt;c&gt; &quot;d&quot; &apos;e&apos; \\f";
  for (const Writer write : {WriteKml, WriteGpx}) {
    const std::string xml = Render(write, track);
    EXPECT_NE(xml.find("<name>" + escaped_xml + "</name>"), std::string::npos);
    EXPECT_NE(xml.find("<name>" + escaped_xml + " track</name>"), std::string::npos);
    EXPECT_EQ(xml.find("a&b"), std::string::npos);
    EXPECT_EQ(xml.find("<c>"), std::string::npos);
  }
  const std::string json = Render(WriteGeoJson, track);
  EXPECT_NE(json.find("\"name\": \"a&b <c> \\\"d\\\" 'e' \\\\f track\""), std::string::npos);

  track.name = std::string("tab\there\x01");
  EXPECT_NE(Render(WriteGeoJson, track).find("\"tab\\u0009here\\u0001\""), std::string::npos);
  EXPECT_NE(Render(WriteKml, track).find("<name>tab\there </name>"), std::string::npos);  // no XML for \x01
}

TEST(GeoFormats, WritesLongitudeFirstWithTheEllipsoidalHeight) {
  const GeoTrack track = MakeTrack(2);
  const std::string kml = Render(WriteKml, track);
  EXPECT_NE(kml.find("<coordinates>\n120.400000000,31.500000000,12.2500\n120.400020000,31.500010000,12.7500\n"),
            std::string::npos);
  const std::string json = Render(WriteGeoJson, track);
  EXPECT_NE(json.find("\"coordinates\": [[120.400000000, 31.500000000, 12.2500], "
                      "[120.400020000, 31.500010000, 12.7500]]"),
            std::string::npos);
  EXPECT_NE(json.find("\"times\": [0.000, 1.000]"), std::string::npos);
  const std::string gpx = Render(WriteGpx, track);
  EXPECT_NE(gpx.find("<trkpt lat=\"31.500000000\" lon=\"120.400000000\"><ele>12.2500</ele></trkpt>"),
            std::string::npos);
}

TEST(GeoFormats, RelativeTimesCarryNoDate) {
  GeoTrack track = MakeTrack(20, kMinAbsoluteTime - 100.0);
  track.no_fix.push_back({kMinAbsoluteTime - 95.0, kMinAbsoluteTime - 90.0, "outage"});
  track.rejected.push_back({kMinAbsoluteTime - 92.0, 31.5, 120.4, 10.0, "eskf"});
  const std::string gpx = Render(WriteGpx, track);
  EXPECT_EQ(gpx.find("<time>"), std::string::npos);
  EXPECT_EQ(gpx.find("utc"), std::string::npos);
  const std::string kml = Render(WriteKml, track);
  EXPECT_EQ(kml.find("<TimeSpan>"), std::string::npos);
  EXPECT_EQ(kml.find("<TimeStamp>"), std::string::npos);
  const std::string json = Render(WriteGeoJson, track);
  EXPECT_EQ(json.find("utc"), std::string::npos);
  EXPECT_NE(json.find("\"t_start\": 99999900.000"), std::string::npos);
}

TEST(GeoFormats, AbsoluteTimesAreUtcOnTheLogsScale) {
  // GPS 1400000000 s is 2024-05-17 16:53:20 on GPS time, 16:53:02 UTC (18 leap seconds).
  GeoTrack track = MakeTrack(3, 1400000000.0, 0.5);
  track.rejected.push_back({1400000000.25, 31.5, 120.4, 10.0, "eskf"});
  const std::string gpx = Render(WriteGpx, track);
  EXPECT_NE(gpx.find("<ele>12.2500</ele><time>2024-05-17T16:53:02.000Z</time></trkpt>"), std::string::npos);
  EXPECT_NE(gpx.find("<ele>13.2500</ele><time>2024-05-17T16:53:03.000Z</time></trkpt>"), std::string::npos);
  EXPECT_NE(gpx.find("<ele>10.0000</ele><time>2024-05-17T16:53:02.250Z</time><name>"), std::string::npos);
  const std::string kml = Render(WriteKml, track);
  EXPECT_NE(kml.find("<TimeSpan><begin>2024-05-17T16:53:02.000Z</begin><end>2024-05-17T16:53:03.000Z</end>"),
            std::string::npos);
  EXPECT_NE(kml.find("<TimeStamp><when>2024-05-17T16:53:02.250Z</when></TimeStamp>"), std::string::npos);
  EXPECT_NE(
      Render(WriteGeoJson, track).find("\"t_start\": 1400000000.000, \"utc_start\": \"2024-05-17T16:53:02.000Z\""),
      std::string::npos);

  GeoWriteOptions unix_utc;
  unix_utc.time_scale = LogTimeScale::kUnixUtc;
  const std::string gpx_unix = Render(WriteGpx, MakeTrack(2, 1700000000.0), unix_utc);
  EXPECT_NE(gpx_unix.find("<time>2023-11-14T22:13:20.000Z</time>"), std::string::npos);
}

TEST(GeoFormats, SkipsNonFiniteSamplesAndFixes) {
  GeoTrack track = MakeTrack(10);
  track.samples[4].lat_deg = std::numeric_limits<double>::quiet_NaN();
  track.samples[7].height_m = std::numeric_limits<double>::infinity();
  track.rejected.push_back({3.0, 31.5, std::numeric_limits<double>::quiet_NaN(), 1.0, "eskf"});
  EXPECT_EQ(Counts(track).lines, 1);
  EXPECT_EQ(Counts(track).points, 0);
  for (const Writer write : {WriteKml, WriteGpx, WriteGeoJson}) {
    const std::string text = Render(write, track);
    EXPECT_EQ(text.find("nan"), std::string::npos);
    EXPECT_EQ(text.find("inf"), std::string::npos);
  }
  EXPECT_EQ(Occurrences(Render(WriteGpx, track), "<trkpt"), 8);
}

TEST(GeoFormats, TheThreeFormatsHaveTheCountedFeatures) {
  GeoTrack track = MakeTrack(200, 1400000000.0, 0.1);
  track.no_fix = {{1400000000.0, 1400000001.0, "gap"}, {1400000005.0, 1400000006.0, "outage"}};
  track.rejected = {{1400000002.0, 31.5, 120.4, 1.0, "eskf"}};
  const GeoFeatureCounts counts = Counts(track);
  EXPECT_EQ(counts.lines, 4);  // gap, track, outage, track
  EXPECT_EQ(counts.points, 1);
  const std::string gpx = Render(WriteGpx, track), kml = Render(WriteKml, track), json = Render(WriteGeoJson, track);
  EXPECT_EQ(Occurrences(gpx, "<trk>"), counts.lines);
  EXPECT_EQ(Occurrences(gpx, "<wpt "), counts.points);
  EXPECT_EQ(Occurrences(gpx, "<trkpt"), 200 + counts.lines - 1);
  EXPECT_EQ(Occurrences(kml, "<LineString>"), counts.lines);
  EXPECT_EQ(Occurrences(kml, "<Point>"), counts.points);
  EXPECT_EQ(Occurrences(kml, "<Folder>"), 2);  // the layers a reader counts apart
  EXPECT_NE(kml.find("<Folder>\n<name>points</name>"), std::string::npos);
  EXPECT_NE(kml.find("<Folder>\n<name>lines</name>"), std::string::npos);
  EXPECT_EQ(Occurrences(json, "\"type\": \"LineString\""), counts.lines);
  EXPECT_EQ(Occurrences(json, "\"type\": \"Point\""), counts.points);
  EXPECT_EQ(Occurrences(json, "\"times\": ["), counts.lines);
}

}  // namespace
}  // namespace gins
