#include "core/io/geo_formats.h"

#include <cmath>
#include <string>
#include <vector>

namespace gins {
namespace {

// A position with its time: a sample's or a rejected fix's.
struct Vertex {
  double t, lat_deg, lon_deg, height_m;
};

// One feature: the vertices [begin, end) of its Layout; one vertex is a point, two or more a line.
struct Feature {
  std::string kind, name, estimator;
  size_t begin = 0, end = 0;
  bool is_line() const { return end - begin >= 2; }
};

// The features of a track, built once for the three writers and CountGeoFeatures, so they cannot disagree.
// Points come first: GPX 1.1 wants its <wpt>s before its <trk>s, and the others keep the same order.
struct Layout {
  std::vector<Vertex> vertices;  // the finite samples, then the finite rejected fixes
  std::vector<Feature> features;
};

bool IsFinite(const Vertex& v) {
  return std::isfinite(v.t) && std::isfinite(v.lat_deg) && std::isfinite(v.lon_deg) && std::isfinite(v.height_m);
}

// printf of one finite double; the buffer holds the longest (%.3f of 1e308: 309 digits and the decimals).
std::string Fixed(double v, int decimals) {
  char buf[400];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}

std::string FeatureName(const GeoTrack& track, const std::string& kind) {
  return track.name.empty() ? kind : track.name + " " + kind;
}

Layout BuildLayout(const GeoTrack& track) {
  Layout layout;
  std::vector<Vertex>& v = layout.vertices;
  for (const GeoSample& s : track.samples) {
    const Vertex x{s.t, s.lat_deg, s.lon_deg, s.height_m};
    if (IsFinite(x)) v.push_back(x);
  }
  const size_t n = v.size();
  for (const GeoFix& f : track.rejected) {
    const Vertex x{f.t, f.lat_deg, f.lon_deg, f.height_m};
    if (!IsFinite(x)) continue;
    const std::string by = f.estimator.empty() ? "" : " (" + f.estimator + ")";
    layout.features.push_back(
        Feature{"rejected_fix", "rejected fix" + by + " t=" + Fixed(f.t, 3), f.estimator, v.size(), v.size() + 1});
    v.push_back(x);
  }
  if (n == 1) layout.features.push_back(Feature{"track", FeatureName(track, "track"), "", 0, 1});
  if (n < 2) return layout;

  // Only intervals that can hold a time: a NaN or reversed one would stall the scan below.
  std::vector<const GeoInterval*> intervals;
  for (const GeoInterval& iv : track.no_fix) {
    if (iv.t0 <= iv.t1) intervals.push_back(&iv);
  }
  // The index of the interval holding t, or -1; one forward scan, as samples and intervals are in time order.
  size_t k = 0;
  auto interval_of = [&](double t) -> long {
    while (k < intervals.size() && intervals[k]->t1 < t) ++k;
    return k < intervals.size() && intervals[k]->t0 <= t ? static_cast<long>(k) : -1;
  };
  // Runs of samples in the same interval (or in none) are the pieces.
  size_t run_begin = 0;
  long run = interval_of(v[0].t);
  for (size_t i = 1; i <= n; ++i) {
    const long here = i < n ? interval_of(v[i].t) : -2;
    if (here == run) continue;
    // Each piece starts at the previous one's last sample, so the lines meet. Only a first piece of one
    // sample can be too short for a line; the next piece starts at that sample anyway.
    const size_t begin = run_begin == 0 ? 0 : run_begin - 1;
    if (i - begin >= 2) {
      const std::string kind = run < 0 ? "track" : intervals[static_cast<size_t>(run)]->kind;
      layout.features.push_back(Feature{kind, FeatureName(track, kind), "", begin, i});
    }
    run_begin = i;
    run = here;
  }
  return layout;
}

// ISO UTC of a log time, or "" for a time without a date.
std::string Utc(double t, const GeoWriteOptions& options) {
  return HasDate(t) ? IsoUtc(LogTimeToUnixUtc(t, options.time_scale), 3) : std::string();
}

// A feature's properties besides its name (which each format has its own element for); one list for the
// three formats, so a GIS client sees the same fields in each.
struct Property {
  std::string key, value;
  bool is_number;
};

std::vector<Property> Properties(const Layout& layout, const Feature& f, const GeoWriteOptions& options) {
  std::vector<Property> props{{"kind", f.kind, false}};
  auto add_time = [&](const char* key, const char* utc_key, double t) {
    props.push_back({key, Fixed(t, 3), true});
    const std::string utc = Utc(t, options);
    if (!utc.empty()) props.push_back({utc_key, utc, false});
  };
  if (f.is_line()) {
    add_time("t_start", "utc_start", layout.vertices[f.begin].t);
    add_time("t_end", "utc_end", layout.vertices[f.end - 1].t);
  } else {
    add_time("t", "utc", layout.vertices[f.begin].t);
  }
  if (!f.estimator.empty()) props.push_back({"estimator", f.estimator, false});
  return props;
}

std::string XmlEscaped(const std::string& s) {
  std::string r;
  for (const char c : s) {
    switch (c) {
      case '&':
        r += "&amp;";
        break;
      case '<':
        r += "&lt;";
        break;
      case '>':
        r += "&gt;";
        break;
      case '"':
        r += "&quot;";
        break;
      case '\'':
        r += "&apos;";
        break;
      default:
        // XML 1.0 has no way to write the other control characters, not even escaped.
        r += static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r' ? ' ' : c;
    }
  }
  return r;
}

// A JSON string literal, quotes included.
std::string JsonString(const std::string& s) {
  std::string r = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      r += '\\';
      r += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(c));
      r += buf;
    } else {
      r += c;
    }
  }
  return r + "\"";
}

void WriteXmlDeclaration(std::FILE* out) { std::fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n", out); }

// KML colours are aabbggrr. KML has no dashed lines: a no-fix piece is red, a gap's translucent.
constexpr char kKmlStyles[] =
    "<Style id=\"track\"><LineStyle><color>ffff0000</color><width>2</width></LineStyle></Style>\n"
    "<Style id=\"outage\"><LineStyle><color>ff0000ff</color><width>3</width></LineStyle></Style>\n"
    "<Style id=\"gap\"><LineStyle><color>990000ff</color><width>3</width></LineStyle></Style>\n"
    "<Style id=\"rejected_fix\"><IconStyle><color>ff0000ff</color><Icon>"
    "<href>http://maps.google.com/mapfiles/kml/shapes/placemark_circle.png</href></Icon></IconStyle></Style>\n";

void WriteKmlPlacemark(const Layout& layout, const Feature& f, const GeoWriteOptions& options, std::FILE* out) {
  std::fprintf(out, "<Placemark>\n<name>%s</name>\n", XmlEscaped(f.name).c_str());
  const std::string utc0 = Utc(layout.vertices[f.begin].t, options);
  const std::string utc1 = Utc(layout.vertices[f.end - 1].t, options);
  if (f.is_line() && !utc0.empty()) {
    std::fprintf(out, "<TimeSpan><begin>%s</begin><end>%s</end></TimeSpan>\n", utc0.c_str(), utc1.c_str());
  } else if (!utc0.empty()) {
    std::fprintf(out, "<TimeStamp><when>%s</when></TimeStamp>\n", utc0.c_str());
  }
  std::fprintf(out, "<styleUrl>#%s</styleUrl>\n<ExtendedData>\n", XmlEscaped(f.kind).c_str());
  for (const Property& p : Properties(layout, f, options)) {
    std::fprintf(out, "<Data name=\"%s\"><value>%s</value></Data>\n", p.key.c_str(), XmlEscaped(p.value).c_str());
  }
  const char* geometry = f.is_line() ? "LineString" : "Point";
  std::fprintf(out, "</ExtendedData>\n<%s><altitudeMode>absolute</altitudeMode><coordinates>\n", geometry);
  for (size_t i = f.begin; i < f.end; ++i) {
    const Vertex& x = layout.vertices[i];
    std::fprintf(out, "%.9f,%.9f,%.4f\n", x.lon_deg, x.lat_deg, x.height_m);
  }
  std::fprintf(out, "</coordinates></%s>\n</Placemark>\n", geometry);
}

// GPX has no place for free properties but <extensions>, whose elements must be in a namespace of their own.
constexpr char kGpxExtensionsNamespace[] = "urn:gins:geo:1";

void WriteGpxExtensions(const std::vector<Property>& props, std::FILE* out) {
  std::fputs("<extensions>", out);
  for (const Property& p : props) {
    std::fprintf(out, "<gins:%s>%s</gins:%s>", p.key.c_str(), XmlEscaped(p.value).c_str(), p.key.c_str());
  }
  std::fputs("</extensions>\n", out);
}

// <ele> and <time>, which open a GPX point's elements in the schema's order.
void WriteGpxPointBody(const Vertex& x, const GeoWriteOptions& options, std::FILE* out) {
  std::fprintf(out, "<ele>%.4f</ele>", x.height_m);
  const std::string utc = Utc(x.t, options);
  if (!utc.empty()) std::fprintf(out, "<time>%s</time>", utc.c_str());
}

}  // namespace

GeoFeatureCounts CountGeoFeatures(const GeoTrack& track) {
  GeoFeatureCounts counts;
  for (const Feature& f : BuildLayout(track).features) ++(f.is_line() ? counts.lines : counts.points);
  return counts;
}

void WriteKml(const GeoTrack& track, const GeoWriteOptions& options, std::FILE* out) {
  const Layout layout = BuildLayout(track);
  WriteXmlDeclaration(out);
  std::fprintf(out, "<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n<name>%s</name>\n%s",
               XmlEscaped(track.name).c_str(), kKmlStyles);
  // One Folder per geometry: a reader (OGR) makes each a layer, so lines and points can be counted apart.
  for (const bool lines : {false, true}) {
    bool open = false;
    for (const Feature& f : layout.features) {
      if (f.is_line() != lines) continue;
      if (!open) std::fprintf(out, "<Folder>\n<name>%s</name>\n", lines ? "lines" : "points");
      open = true;
      WriteKmlPlacemark(layout, f, options, out);
    }
    if (open) std::fputs("</Folder>\n", out);
  }
  std::fputs("</Document>\n</kml>\n", out);
}

void WriteGpx(const GeoTrack& track, const GeoWriteOptions& options, std::FILE* out) {
  const Layout layout = BuildLayout(track);
  WriteXmlDeclaration(out);
  std::fprintf(out,
               "<gpx version=\"1.1\" creator=\"gins\" xmlns=\"http://www.topografix.com/GPX/1/1\" "
               "xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" xsi:schemaLocation=\"http://www.topografix"
               ".com/GPX/1/1 http://www.topografix.com/GPX/1/1/gpx.xsd\" xmlns:gins=\"%s\">\n"
               "<metadata><name>%s</name></metadata>\n",
               kGpxExtensionsNamespace, XmlEscaped(track.name).c_str());
  // Points come first in the layout, as the schema wants every <wpt> before any <trk>.
  for (const Feature& f : layout.features) {
    const std::string name = XmlEscaped(f.name), kind = XmlEscaped(f.kind);
    const std::vector<Property> props = Properties(layout, f, options);
    if (!f.is_line()) {
      const Vertex& x = layout.vertices[f.begin];
      std::fprintf(out, "<wpt lat=\"%.9f\" lon=\"%.9f\">", x.lat_deg, x.lon_deg);
      WriteGpxPointBody(x, options, out);
      std::fprintf(out, "<name>%s</name><type>%s</type>", name.c_str(), kind.c_str());
      WriteGpxExtensions(props, out);
      std::fputs("</wpt>\n", out);
      continue;
    }
    std::fprintf(out, "<trk>\n<name>%s</name>\n<type>%s</type>\n", name.c_str(), kind.c_str());
    WriteGpxExtensions(props, out);
    std::fputs("<trkseg>\n", out);
    for (size_t i = f.begin; i < f.end; ++i) {
      const Vertex& x = layout.vertices[i];
      std::fprintf(out, "<trkpt lat=\"%.9f\" lon=\"%.9f\">", x.lat_deg, x.lon_deg);
      WriteGpxPointBody(x, options, out);
      std::fputs("</trkpt>\n", out);
    }
    std::fputs("</trkseg>\n</trk>\n", out);
  }
  std::fputs("</gpx>\n", out);
}

void WriteGeoJson(const GeoTrack& track, const GeoWriteOptions& options, std::FILE* out) {
  const Layout layout = BuildLayout(track);
  // "name" is a foreign member (RFC 7946 §6.1) that GDAL takes as the layer's name.
  std::fprintf(out, "{\"type\": \"FeatureCollection\", \"name\": %s, \"features\": [", JsonString(track.name).c_str());
  const char* feature_sep = "\n";
  for (const Feature& f : layout.features) {
    std::fprintf(out, "%s{\"type\": \"Feature\", \"properties\": {\"name\": %s", feature_sep,
                 JsonString(f.name).c_str());
    feature_sep = ",\n";
    for (const Property& p : Properties(layout, f, options)) {
      std::fprintf(out, ", %s: %s", JsonString(p.key).c_str(),
                   p.is_number ? p.value.c_str() : JsonString(p.value).c_str());
    }
    if (f.is_line()) {
      // Each vertex's time, for a reader to match the vertices to the log (GeoJSON has no M coordinate).
      std::fputs(", \"times\": [", out);
      for (size_t i = f.begin; i < f.end; ++i) {
        std::fprintf(out, "%s%.3f", i == f.begin ? "" : ", ", layout.vertices[i].t);
      }
      std::fputs("]", out);
    }
    std::fprintf(out, "}, \"geometry\": {\"type\": \"%s\", \"coordinates\": ", f.is_line() ? "LineString" : "Point");
    if (f.is_line()) std::fputs("[", out);
    for (size_t i = f.begin; i < f.end; ++i) {
      const Vertex& x = layout.vertices[i];
      std::fprintf(out, "%s[%.9f, %.9f, %.4f]", i == f.begin ? "" : ", ", x.lon_deg, x.lat_deg, x.height_m);
    }
    std::fputs(f.is_line() ? "]}}" : "}}", out);
  }
  std::fputs("\n]}\n", out);
}

}  // namespace gins
