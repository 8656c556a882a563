#include "scene/SceneLoader.h"

#include <fmt/format.h>
#include <pugixml.hpp>
#include <spdlog/spdlog.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "image/Image.h"
#include "materials/BsdfFactory.h"
#include "scene/MitsubaPlugins.h"
#include "scene/NameTables.h"
#include "scene/Properties.h"

namespace envgi {

namespace fs = std::filesystem;

namespace {

struct SourceFile {
  std::string path;
  std::string text;
  int lineOf(ptrdiff_t offset) const {
    int line = 1;
    for (ptrdiff_t i = 0; i < offset && i < ptrdiff_t(text.size()); ++i)
      if (text[size_t(i)] == '\n') ++line;
    return line;
  }
};

// A property element (<float name=... value=...>, <rgb>, <transform>, ...) of a plugin.
struct Prop {
  pugi::xml_node node;
  std::string tag;
  bool used = false;
};

class Loader {
 public:
  Loader(Scene& scene, const std::map<std::string, std::string>& defines) : scene_(scene), cliDefines_(defines) {
    params_ = defines;
  }

  void loadFile(const std::string& path, int depth) {
    if (depth > 16) throw std::runtime_error(path + ": includes nested too deeply (a cycle?)");
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error("cannot open scene file '" + path + "'");
    loadText(path, std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>()), depth);
  }

  // XML text read as the file `path` (its name in messages, its folder the base of relative
  // file names).
  void loadText(const std::string& path, std::string text, int depth) {
    auto src = std::make_unique<SourceFile>();
    src->path = path;
    src->text = std::move(text);
    auto doc = std::make_unique<pugi::xml_document>();
    pugi::xml_parse_result r = doc->load_buffer(src->text.data(), src->text.size());
    if (!r) throw std::runtime_error(fmt::format("{}:{}: XML error: {}", path, src->lineOf(r.offset), r.description()));
    files_.push_back(std::move(src));
    docs_.push_back(std::move(doc));
    const SourceFile* file = files_.back().get();
    pugi::xml_node root = docs_.back()->document_element();
    if (std::string(root.name()) != "scene") fail(file, root, "the root element must be <scene>");
    checkAttrs(file, root, {"version"});
    std::string version = root.attribute("version").as_string();
    if (version.empty()) fail(file, root, "<scene> needs a version attribute");
    if (version[0] != '3' && version[0] != '2')
      warnOnce(fmt::format("{}: scene version {} is not 3.x; reading it as 3.0.0", path, version));
    for (pugi::xml_node n : root.children()) {
      if (n.type() != pugi::node_element) continue;
      topLevel(file, n, depth);
    }
  }

  void finish() {
    if (!haveSensor_) throw std::runtime_error(files_.front()->path + ": the scene has no <sensor>");
    if (instances_ > 0)
      spdlog::info("{} instances placed {} shapes; their meshes share {} shapegroup meshes ({} triangles stored for {} placed)",
                   instances_, instancedShapes_, scene_.prototypes.size(), prototypeTriangles(), instancedTriangles());
    // A -D value that nothing in the scene reads (a misspelt name, or a parameter of another
    // scene) leaves the render as it would be without it: said once, with the nearest name.
    std::vector<std::string> names(paramNames_.begin(), paramNames_.end());
    for (const auto& [name, value] : cliDefines_) {
      if (paramNames_.count(name)) continue;
      warnOnce(fmt::format("-D {}={}: {} has no parameter '{}'{}, so the value is not used", name, value,
                           files_.front()->path, name, didYouMean(name, names)));
    }
  }

 private:
  Scene& scene_;
  std::map<std::string, std::string> cliDefines_, params_;
  std::vector<std::unique_ptr<SourceFile>> files_;
  std::vector<std::unique_ptr<pugi::xml_document>> docs_;
  struct NamedIndex {
    int index;          // into scene_.bsdfs or scene_.textures
    std::string where;  // "file:line" of its definition, for a duplicate's error
  };
  std::map<std::string, NamedIndex> bsdfIds_, textureIds_;
  std::set<std::string> warned_;
  // Declared by <default> or read as $name, in any file (mutable: the const substitution records it).
  mutable std::set<std::string> paramNames_;
  std::set<std::string> asked_;  // every property name the loader has looked for: "did you mean" candidates
  bool haveSensor_ = false;

  [[noreturn]] void fail(const SourceFile* f, pugi::xml_node n, const std::string& what) const {
    throw std::runtime_error(fmt::format("{}:{}: {}", f->path, f->lineOf(n.offset_debug()), what));
  }
  // Re-raises an error from below with this element's file and line, unless it has them already.
  [[noreturn]] void rethrowAt(const SourceFile* f, pugi::xml_node n, const std::runtime_error& e) const {
    std::string what = e.what();
    if (what.rfind(f->path, 0) == 0) throw e;
    fail(f, n, what);
  }
  void warnOnce(const std::string& msg) {
    if (warned_.insert(msg).second) spdlog::warn("{}", msg);
  }
  void checkAttrs(const SourceFile* f, pugi::xml_node n, std::initializer_list<const char*> allowed) const {
    for (pugi::xml_attribute a : n.attributes()) {
      bool ok = false;
      for (const char* x : allowed) ok = ok || std::string(a.name()) == x;
      if (!ok) fail(f, n, fmt::format("unexpected attribute '{}' on <{}>", a.name(), n.name()));
    }
  }
  // Attribute value with $name parameters substituted.
  std::string attr(const SourceFile* f, pugi::xml_node n, const char* name, bool required = true) const {
    pugi::xml_attribute a = n.attribute(name);
    if (!a) {
      if (required) fail(f, n, fmt::format("<{}> needs a '{}' attribute", n.name(), name));
      return "";
    }
    std::string v = a.as_string(), out;
    for (size_t i = 0; i < v.size(); ++i) {
      if (v[i] != '$') {
        out += v[i];
        continue;
      }
      size_t j = i + 1;
      while (j < v.size() && (std::isalnum((unsigned char)v[j]) || v[j] == '_')) ++j;
      std::string key = v.substr(i + 1, j - i - 1);
      paramNames_.insert(key);
      auto it = params_.find(key);
      if (it == params_.end()) fail(f, n, fmt::format("undefined parameter '${}'", key));
      out += it->second;
      i = j - 1;
    }
    return out;
  }

  float parseFloat(const SourceFile* f, pugi::xml_node n, const std::string& s) const {
    try {
      return parseFloatValue(s);
    } catch (const std::runtime_error& e) {
      fail(f, n, e.what());
    }
  }
  std::vector<float> parseList(const SourceFile* f, pugi::xml_node n, const std::string& s) const {
    std::vector<float> out;
    std::string tok;
    std::stringstream ss(s);
    while (std::getline(ss, tok, ',')) {
      std::stringstream ws(tok);
      std::string w;
      while (ws >> w) out.push_back(parseFloat(f, n, w));
    }
    return out;
  }
  Vec3f parseVec(const SourceFile* f, pugi::xml_node n, const std::string& s) const {
    std::vector<float> v = parseList(f, n, s);
    if (v.size() == 1) return Vec3f(v[0]);
    if (v.size() != 3) fail(f, n, fmt::format("expected 3 numbers, got '{}'", s));
    return {v[0], v[1], v[2]};
  }

  // ---- properties --------------------------------------------------------------------------
  using Props = std::map<std::string, Prop>;

  Props collectProps(const SourceFile* f, pugi::xml_node parent) const {
    static const std::set<std::string> propTags = {"float", "integer", "boolean", "string", "rgb",
                                                   "spectrum", "point", "vector", "transform"};
    Props props;
    for (pugi::xml_node c : parent.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (!propTags.count(tag)) continue;
      if (tag == "transform") checkAttrs(f, c, {"name"});
      else if (tag == "point" || tag == "vector") checkAttrs(f, c, {"name", "value", "x", "y", "z"});
      else checkAttrs(f, c, {"name", "value"});
      std::string name = attr(f, c, "name");
      if (props.count(name)) fail(f, c, fmt::format("property '{}' given twice", name));
      props[name] = Prop{c, tag, false};
    }
    return props;
  }
  Prop* find(Props& p, const std::string& name) {
    asked_.insert(name);
    auto it = p.find(name);
    if (it == p.end()) return nullptr;
    it->second.used = true;
    return &it->second;
  }
  void expectTag(const SourceFile* f, const Prop& p, std::initializer_list<const char*> tags) const {
    for (const char* t : tags)
      if (p.tag == t) return;
    fail(f, p.node, fmt::format("property '{}' cannot be a <{}>", p.node.attribute("name").as_string(), p.tag));
  }
  float getFloat(const SourceFile* f, Props& p, const std::string& name, float def) {
    Prop* x = find(p, name);
    if (!x) return def;
    expectTag(f, *x, {"float", "integer"});
    return parseFloat(f, x->node, attr(f, x->node, "value"));
  }
  int getInt(const SourceFile* f, Props& p, const std::string& name, int def) {
    Prop* x = find(p, name);
    if (!x) return def;
    expectTag(f, *x, {"integer"});
    try {
      return parseIntValue(attr(f, x->node, "value"));
    } catch (const std::runtime_error& e) {
      fail(f, x->node, e.what());
    }
  }
  bool getBool(const SourceFile* f, Props& p, const std::string& name, bool def) {
    Prop* x = find(p, name);
    if (!x) return def;
    expectTag(f, *x, {"boolean"});
    try {
      return parseBoolValue(attr(f, x->node, "value"));
    } catch (const std::runtime_error& e) {
      fail(f, x->node, e.what());
    }
  }
  std::string getString(const SourceFile* f, Props& p, const std::string& name, const std::string& def) {
    Prop* x = find(p, name);
    if (!x) return def;
    expectTag(f, *x, {"string"});
    return attr(f, x->node, "value");
  }
  Color getColor(const SourceFile* f, Props& p, const std::string& name, Color def) {
    Prop* x = find(p, name);
    if (!x) return def;
    expectTag(f, *x, {"rgb", "spectrum", "float"});
    std::string v = attr(f, x->node, "value");
    if (x->tag == "spectrum" && v.find(':') != std::string::npos)
      fail(f, x->node, "spectral data (wavelength:value) is not supported; give an <rgb>");
    Color c = parseVec(f, x->node, v);
    if (c.x < 0.f || c.y < 0.f || c.z < 0.f) fail(f, x->node, fmt::format("'{}' must not be negative", name));
    return c;
  }
  Vec3f getPoint(const SourceFile* f, Props& p, const std::string& name, Vec3f def) {
    Prop* x = find(p, name);
    if (!x) return def;
    expectTag(f, *x, {"point", "vector"});
    if (x->node.attribute("value")) return parseVec(f, x->node, attr(f, x->node, "value"));
    return {parseFloat(f, x->node, attr(f, x->node, "x", false).empty() ? "0" : attr(f, x->node, "x")),
            parseFloat(f, x->node, attr(f, x->node, "y", false).empty() ? "0" : attr(f, x->node, "y")),
            parseFloat(f, x->node, attr(f, x->node, "z", false).empty() ? "0" : attr(f, x->node, "z"))};
  }
  float getIor(const SourceFile* f, Props& p, const std::string& name, float def) {
    Prop* x = find(p, name);
    if (!x) return def;
    expectTag(f, *x, {"float", "string"});
    std::string v = attr(f, x->node, "value");
    // Mitsuba 3's names with its values, and envgi's "glass" (bk7) and "sapphire".
    static const std::map<std::string, float> named = {
        {"vacuum", 1.f},          {"helium", 1.000036f},    {"hydrogen", 1.000132f},  {"air", 1.000277f},
        {"carbon dioxide", 1.00045f}, {"water", 1.333f},    {"acetone", 1.36f},       {"ethanol", 1.361f},
        {"carbon tetrachloride", 1.461f}, {"glycerol", 1.4729f}, {"benzene", 1.501f}, {"silicone oil", 1.52045f},
        {"bromine", 1.661f},      {"water ice", 1.31f},     {"fused quartz", 1.458f}, {"pyrex", 1.47f},
        {"acrylic glass", 1.49f}, {"polypropylene", 1.49f}, {"bk7", 1.5046f},         {"sodium chloride", 1.544f},
        {"amber", 1.55f},         {"pet", 1.575f},          {"diamond", 2.419f},      {"glass", 1.5046f},
        {"sapphire", 1.77f}};
    if (x->tag == "string") {
      auto it = named.find(v);
      if (it == named.end()) fail(f, x->node, fmt::format("unknown index of refraction '{}'", v));
      return it->second;
    }
    float ior = parseFloat(f, x->node, v);
    if (ior <= 0.f) fail(f, x->node, "an index of refraction must be positive");
    return ior;
  }
  // int_ior / ext_ior of a dielectric interface. Equal indices are no interface at all (the
  // microfacet half vector of a straight transmission is then zero): refused, as Mitsuba does.
  float interfaceIor(const SourceFile* f, pugi::xml_node n, Props& p, float intDefault, float extDefault) {
    float in = getIor(f, p, "int_ior", intDefault), out = getIor(f, p, "ext_ior", extDefault);
    if (in == out) fail(f, n, fmt::format("int_ior and ext_ior must differ (both are {})", in));
    return in / out;
  }
  Transform getTransform(const SourceFile* f, Props& p, const std::string& name) {
    Prop* x = find(p, name);
    if (!x) return Transform{};
    expectTag(f, *x, {"transform"});
    return parseTransform(f, x->node);
  }
  // What envgi did not read: a property that Mitsuba's plugin takes is left out with a warning
  // (a Mitsuba scene may set it); any other is an error, as Mitsuba makes it, since it is most
  // likely a misspelt name whose value would silently go unused.
  void reportUnused(const SourceFile* f, const Props& p, const std::string& kind, const std::string& type) {
    for (const auto& [name, prop] : p) {
      if (prop.used) continue;
      std::string error = unknownPropertyError(kind, type, name, asked_);
      if (!error.empty()) fail(f, prop.node, error);
      warnOnce(fmt::format("{}:{}: property '{}' of {} '{}' is not supported and was ignored", f->path,
                           f->lineOf(prop.node.offset_debug()), name, kind, type));
    }
  }
  // Empty where Mitsuba's plugin takes the property; else the error, with the nearest of
  // Mitsuba's names and those asked for.
  static std::string unknownPropertyError(const std::string& kind, const std::string& type, const std::string& name,
                                          const std::set<std::string>& asked) {
    if (mitsubaPluginTakes(kind, type, name)) return "";
    std::vector<std::string> known = mitsubaPluginProperties(kind, type);
    known.insert(known.end(), asked.begin(), asked.end());
    return fmt::format("{} '{}' has no property '{}'{}", kind, type, name, didYouMean(name, known));
  }

  // Mitsuba composes the operations in order: each one applies after the ones before it.
  Transform parseTransform(const SourceFile* f, pugi::xml_node n) {
    Transform t;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      Transform op;
      try {
        if (tag == "translate") {
          checkAttrs(f, c, {"value", "x", "y", "z"});
          op = translate(xyz(f, c, 0.f));
        } else if (tag == "scale") {
          checkAttrs(f, c, {"value", "x", "y", "z"});
          op = scale(xyz(f, c, 1.f));
        } else if (tag == "rotate") {
          checkAttrs(f, c, {"value", "x", "y", "z", "angle"});
          op = rotate(xyz(f, c, 0.f), parseFloat(f, c, attr(f, c, "angle")));
        } else if (tag == "matrix") {
          checkAttrs(f, c, {"value"});
          std::vector<float> v = parseList(f, c, attr(f, c, "value"));
          if (v.size() != 16 && v.size() != 9) fail(f, c, "a matrix needs 16 (or 9) numbers");
          Matrix4 m;
          if (v.size() == 16) {
            for (int i = 0; i < 16; ++i) m.m[i / 4][i % 4] = v[size_t(i)];
          } else {
            for (int i = 0; i < 9; ++i) m.m[i / 3][i % 3] = v[size_t(i)];
          }
          op = makeTransform(m);
        } else if (tag == "lookat") {
          checkAttrs(f, c, {"origin", "target", "up"});
          Vec3f up = c.attribute("up") ? parseVec(f, c, attr(f, c, "up")) : Vec3f(0.f, 1.f, 0.f);
          op = lookAt(parseVec(f, c, attr(f, c, "origin")), parseVec(f, c, attr(f, c, "target")), up);
        } else {
          fail(f, c, fmt::format("unknown transform operation <{}>", tag));
        }
      } catch (const std::runtime_error& e) {
        rethrowAt(f, c, e);
      }
      t = op * t;
    }
    return t;
  }
  Vec3f xyz(const SourceFile* f, pugi::xml_node c, float def) const {
    if (c.attribute("value")) {
      std::vector<float> v = parseList(f, c, attr(f, c, "value"));
      if (v.size() == 1) return Vec3f(v[0]);
      if (v.size() == 3) return {v[0], v[1], v[2]};
      fail(f, c, "expected 1 or 3 numbers");
    }
    auto comp = [&](const char* k) { return c.attribute(k) ? parseFloat(f, c, attr(f, c, k)) : def; };
    return {comp("x"), comp("y"), comp("z")};
  }

  // ---- elements ------------------------------------------------------------------------------
  // Files a top-level element's index under its id, for <ref>s that follow.
  void nameTopLevel(const SourceFile* f, pugi::xml_node n, int index, std::map<std::string, NamedIndex>& ids,
                    const char* kind) {
    std::string name = attr(f, n, "id", false);
    std::string where = fmt::format("{}:{}", f->path, f->lineOf(n.offset_debug()));
    if (name.empty()) {
      warnOnce(fmt::format("{}: a top-level <{}> without an id is never used", where, n.name()));
      return;
    }
    // As Mitsuba: a second definition of an id is an error, not a silent replacement.
    auto [it, fresh] = ids.emplace(name, NamedIndex{index, where});
    if (!fresh) fail(f, n, fmt::format("duplicate {} id '{}' (first defined at {})", kind, name, it->second.where));
  }

  void topLevel(const SourceFile* f, pugi::xml_node n, int depth) {
    std::string tag = n.name();
    if (tag == "default") {
      checkAttrs(f, n, {"name", "value"});
      std::string name = attr(f, n, "name");
      paramNames_.insert(name);
      if (!cliDefines_.count(name)) params_[name] = attr(f, n, "value");
    } else if (tag == "include") {
      checkAttrs(f, n, {"filename"});
      fs::path p = fs::path(f->path).parent_path() / attr(f, n, "filename");
      if (!fs::exists(p)) fail(f, n, fmt::format("included file '{}' does not exist", p.string()));
      loadFile(p.string(), depth + 1);
    } else if (tag == "integrator") {
      integrator(f, n);
    } else if (tag == "sensor") {
      sensor(f, n);
    } else if (tag == "emitter") {
      emitter(f, n, nullptr);
    } else if (tag == "shape") {
      shape(f, n);
    } else if (tag == "bsdf") {
      nameTopLevel(f, n, bsdf(f, n), bsdfIds_, "BSDF");
    } else if (tag == "texture") {
      nameTopLevel(f, n, texture(f, n), textureIds_, "texture");
    } else if (tag == "medium" || tag == "phase") {
      ignoreMedium(f, n);
    } else {
      const std::vector<std::string> elements = {"default", "include", "integrator", "sensor", "emitter",
                                                 "shape",   "bsdf",    "texture",    "medium", "phase"};
      fail(f, n, fmt::format("unknown element <{}>{}", tag, didYouMean(tag, elements, "<", ">")));
    }
  }

  // Participating media are not rendered: a <medium> (or <phase>) anywhere, and a shape's
  // <ref name="interior|exterior">, are one warning each, and the scene renders without them.
  void ignoreMedium(const SourceFile* f, pugi::xml_node n) {
    warnOnce(fmt::format("{}:{}: <{}>: participating media are not supported and were ignored", f->path,
                         f->lineOf(n.offset_debug()), n.name()));
  }

  void integrator(const SourceFile* f, pugi::xml_node n) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    if (type == "aov") return aovIntegrator(f, n);
    Props p = collectProps(f, n);
    try {
      Properties props = scalarProperties(f, n, p);
      scene_.integrator = IntegratorSettings::fromProperties(findIntegrator(type), props);
      if (type == "volpath" || type == "volpathmis")
        spdlog::info("integrator '{}' is read as 'path': envgi has no media, and its path lets shadow rays through "
                     "masks as {} does", type, type);
      for (const auto& [name, where] : props.unused()) {
        std::string error = unknownPropertyError("integrator", type, name, props.asked());
        if (!error.empty()) throw std::runtime_error(where + ": " + error);
        warnOnce(fmt::format("{}: property '{}' of integrator '{}' is not supported and was ignored", where, name, type));
      }
    } catch (const std::runtime_error& e) {
      rethrowAt(f, n, e);
    }
    for (pugi::xml_node c : n.children())
      if (c.type() == pugi::node_element && !isPropTag(c.name())) fail(f, c, fmt::format("unexpected <{}> in <integrator>", c.name()));
  }

  // Mitsuba's aov integrator: its `aovs` list, written as channels beside the image, and one
  // nested integrator that renders the image (Mitsuba allows several, each its own image).
  void aovIntegrator(const SourceFile* f, pugi::xml_node n) {
    Props p = collectProps(f, n);
    std::string spec = getString(f, p, "aovs", "");
    try {
      scene_.aovs = parseAovs(spec);
    } catch (const std::runtime_error& e) {
      rethrowAt(f, n, e);
    }
    reportUnused(f, p, "integrator", "aov");
    pugi::xml_node inner;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element || isPropTag(c.name())) continue;
      if (std::string(c.name()) != "integrator") fail(f, c, fmt::format("unexpected <{}> in <integrator>", c.name()));
      if (inner) fail(f, c, "envgi renders one image: an aov integrator holds one integrator, not several");
      if (std::string(c.attribute("type").as_string()) == "aov") fail(f, c, "an aov integrator inside an aov integrator");
      inner = c;
    }
    if (!inner) fail(f, n, "an aov integrator needs a nested <integrator> for the image (e.g. <integrator type=\"path\"/>)");
    integrator(f, inner);
  }

  // A plugin's properties as plain values, each with its own file and line.
  Properties scalarProperties(const SourceFile* f, pugi::xml_node n, Props& p) {
    Properties out(fmt::format("{}:{}", f->path, f->lineOf(n.offset_debug())));
    for (auto& [name, prop] : p) {
      prop.used = true;
      out.set(name, prop.tag, attr(f, prop.node, "value", false),
              fmt::format("{}:{}", f->path, f->lineOf(prop.node.offset_debug())));
    }
    return out;
  }

  static bool isPropTag(const std::string& t) {
    return t == "float" || t == "integer" || t == "boolean" || t == "string" || t == "rgb" || t == "spectrum" ||
           t == "point" || t == "vector" || t == "transform";
  }

  std::array<int, 4> crop_{};  // the film's crop window: x, y, width, height (film() reads it)

  void sensor(const SourceFile* f, pugi::xml_node n) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    if (type != "perspective" && type != "thinlens" && type != "orthographic")
      fail(f, n, fmt::format("unknown sensor type '{}' (perspective, thinlens, orthographic)", type));
    haveSensor_ = true;
    Props p = collectProps(f, n);
    Camera& cam = scene_.camera;
    const bool ortho = type == "orthographic";
    cam.orthographic = ortho;
    // Mitsuba's orthographic camera has no field of view: to_world's scale sizes its view.
    float fov = ortho ? 45.f : getFloat(f, p, "fov", 45.f);
    if (!(fov > 0.f && fov < 180.f)) fail(f, n, "fov must be between 0 and 180 degrees");
    std::string axis = ortho ? "x" : getString(f, p, "fov_axis", "x");
    cam.nearClip = getFloat(f, p, "near_clip", 0.01f);
    cam.farClip = getFloat(f, p, "far_clip", 10000.f);
    if (!(cam.nearClip > 0.f && cam.farClip > cam.nearClip)) fail(f, n, "need 0 < near_clip < far_clip");
    cam.toWorld = getTransform(f, p, "to_world");
    cam.apertureRadius = 0.f;
    cam.focusDistance = cam.farClip;
    if (type == "thinlens") {
      // Mitsuba requires the radius and focuses at far_clip unless told.
      if (!find(p, "aperture_radius")) fail(f, n, "thinlens needs an 'aperture_radius'");
      cam.apertureRadius = getFloat(f, p, "aperture_radius", 0.f);
      cam.focusDistance = getFloat(f, p, "focus_distance", cam.farClip);
      if (!(cam.apertureRadius >= 0.f && cam.apertureRadius < 1e30f)) fail(f, n, "aperture_radius must be >= 0");
      if (!(cam.focusDistance > 0.f && cam.focusDistance < 1e30f)) fail(f, n, "focus_distance must be positive");
    }
    reportUnused(f, p, "sensor", type);
    cam.width = 768;
    cam.height = 576;
    crop_ = {0, 0, cam.width, cam.height};
    cam.filmWidth = cam.filmHeight = cam.cropX = cam.cropY = 0;
    cam.filter = makeFilter(FilterType::Gaussian);
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (tag == "film") film(f, c);
      else if (tag == "sampler") sampler(f, c);
      else if (!isPropTag(tag)) fail(f, c, fmt::format("unexpected <{}> in <sensor>", tag));
    }
    float aspect = float(cam.width) / float(cam.height);
    float t = ortho ? 1.f : std::tan(0.5f * fov * kPi / 180.f);
    if (axis == "x") {
      cam.tanHalfX = t;
      cam.tanHalfY = t / aspect;
    } else if (axis == "y") {
      cam.tanHalfY = t;
      cam.tanHalfX = t * aspect;
    } else if (axis == "diagonal") {
      float d = std::sqrt(1.f + 1.f / (aspect * aspect));
      cam.tanHalfX = t / d;
      cam.tanHalfY = cam.tanHalfX / aspect;
    } else if (axis == "smaller" || axis == "larger") {
      bool xIsIt = (axis == "smaller") == (aspect <= 1.f);
      cam.tanHalfX = xIsIt ? t : t * aspect;
      cam.tanHalfY = xIsIt ? t / aspect : t;
    } else {
      fail(f, n, fmt::format("unknown fov_axis '{}' (x, y, diagonal, smaller, larger)", axis));
    }
    if (crop_[0] != 0 || crop_[1] != 0 || crop_[2] != cam.width || crop_[3] != cam.height) {
      cam.filmWidth = cam.width;
      cam.filmHeight = cam.height;
      cam.cropX = crop_[0];
      cam.cropY = crop_[1];
      cam.width = crop_[2];
      cam.height = crop_[3];
    }
  }

  void film(const SourceFile* f, pugi::xml_node n) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    if (type != "hdrfilm") fail(f, n, fmt::format("unknown film type '{}' (hdrfilm)", type));
    Props p = collectProps(f, n);
    Camera& cam = scene_.camera;
    cam.width = getInt(f, p, "width", 768);
    cam.height = getInt(f, p, "height", 576);
    if (cam.width <= 0 || cam.height <= 0 || cam.width > 32768 || cam.height > 32768)
      fail(f, n, "film width and height must be between 1 and 32768");
    // Mitsuba's crop window, applied once the sensor has its aspect from the whole film.
    crop_ = {getInt(f, p, "crop_offset_x", 0), getInt(f, p, "crop_offset_y", 0), getInt(f, p, "crop_width", cam.width),
             getInt(f, p, "crop_height", cam.height)};
    if (!(crop_[0] >= 0 && crop_[1] >= 0 && crop_[2] >= 1 && crop_[3] >= 1 && crop_[2] <= cam.width - crop_[0] &&
          crop_[3] <= cam.height - crop_[1]))
      fail(f, n, fmt::format("the crop window ({}, {}) + {} x {} does not lie within the {} x {} film", crop_[0], crop_[1],
                             crop_[2], crop_[3], cam.width, cam.height));
    // envgi draws each pixel's samples from its filter, so border pixels always see the whole
    // filter: what sample_border (high_quality_edges in Mitsuba 0.6) turns on in Mitsuba.
    // The others change only how Mitsuba writes its file; each is still read with its type, so
    // that a misspelt value is the error it is in Mitsuba.
    for (const char* harmless : {"banner", "high_quality_edges", "sample_border"}) getBool(f, p, harmless, false);
    for (const char* harmless : {"file_format", "component_format"}) getString(f, p, harmless, "");
    // Mitsuba's pixel formats: envgi writes RGB, with an A channel (in an .exr) where the format
    // has alpha. Mitsuba's default is rgba; envgi's stays rgb unless the scene asks.
    std::string format = getString(f, p, "pixel_format", "rgb");
    if (format != "rgb" && format != "rgba" && format != "luminance" && format != "luminance_alpha" &&
        format != "xyz" && format != "xyza")
      fail(f, n, fmt::format("unknown pixel_format '{}' (rgb, rgba, luminance, luminance_alpha, xyz, xyza)", format));
    scene_.filmAlpha = format == "rgba" || format == "xyza" || format == "luminance_alpha";
    if (format != "rgb" && format != "rgba")
      warnOnce(fmt::format("{}:{}: pixel_format '{}' is written as {}", f->path, f->lineOf(n.offset_debug()), format,
                           scene_.filmAlpha ? "rgba" : "rgb"));
    reportUnused(f, p, "film", type);
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (tag == "rfilter") {
        checkAttrs(f, c, {"type", "name", "id"});
        std::string t = attr(f, c, "type");
        FilterType ft{};
        try {
          ft = findName(kFilterNames, t, "rfilter type");
        } catch (const std::runtime_error& e) {
          fail(f, c, e.what());
        }
        Props fp = collectProps(f, c);
        FilterParams params;  // each type reads its own, with Mitsuba's defaults
        if (ft == FilterType::Tent) params.radius = getFloat(f, fp, "radius", params.radius);
        if (ft == FilterType::Gaussian) params.stddev = getFloat(f, fp, "stddev", params.stddev);
        if (ft == FilterType::Mitchell) {
          params.b = getFloat(f, fp, "B", params.b);
          params.c = getFloat(f, fp, "C", params.c);
        }
        if (ft == FilterType::Lanczos) params.lobes = getInt(f, fp, "lobes", params.lobes);
        reportUnused(f, fp, "rfilter", t);
        try {
          cam.filter = makeFilter(ft, params);
        } catch (const std::invalid_argument& e) {
          fail(f, c, fmt::format("rfilter '{}': {}", t, e.what()));
        }
      } else if (!isPropTag(tag)) {
        fail(f, c, fmt::format("unexpected <{}> in <film>", tag));
      }
    }
  }

  void sampler(const SourceFile* f, pugi::xml_node n) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    SamplerSettings& s = scene_.sampler;
    try {
      s.type = findSampler(type);
    } catch (const std::runtime_error& e) {
      fail(f, n, e.what());
    }
    Props p = collectProps(f, n);
    s.sampleCount = getInt(f, p, "sample_count", 4);
    s.seed = uint32_t(getInt(f, p, "seed", 0));
    find(p, "jitter");
    if (s.sampleCount <= 0) fail(f, n, "sample_count must be positive");
    reportUnused(f, p, "sampler", type);
  }

  // A light's direction as a unit vector; zero, or so long that its length overflows, is an error.
  Vec3f unitDirection(const SourceFile* f, pugi::xml_node n, Vec3f d, const char* what) {
    if (!(lengthSq(d) > 0.f) || !std::isfinite(lengthSq(d))) fail(f, n, what);
    return normalize(d);
  }

  // Mitsuba's `directional` (irradiance, travelling along `direction` or to_world's +z) and
  // `point` (intensity, at `position` or to_world's origin); giving both forms is an error there.
  DeltaLight deltaLight(const SourceFile* f, pugi::xml_node n, const std::string& type, Props& p) {
    const char* where = type == "point" ? "position" : "direction";
    bool explicitForm = p.count(where) > 0, transformed = p.count("to_world") > 0;
    if (explicitForm && transformed)
      fail(f, n, fmt::format("a '{}' emitter takes '{}' or 'to_world', not both", type, where));
    Transform t = getTransform(f, p, "to_world");
    DeltaLight l;
    l.point = type == "point";
    if (l.point) {
      l.v = explicitForm ? getPoint(f, p, "position", Vec3f(0.f)) : t.point(Vec3f(0.f));
      l.value = getColor(f, p, "intensity", Color(1.f));
    } else {
      Vec3f d = explicitForm ? getPoint(f, p, "direction", Vec3f(0.f)) : t.vector(Vec3f(0.f, 0.f, 1.f));
      l.v = unitDirection(f, n, d, "a 'directional' emitter needs a non-zero, finite direction");
      l.value = getColor(f, p, "irradiance", Color(1.f));
    }
    return l;
  }

  // Mitsuba's `spot`: at to_world's origin, shining along its +z, full `intensity` within
  // `beam_width` degrees of the axis (3/4 of the cutoff unless given), none beyond `cutoff_angle`.
  DeltaLight spotLight(const SourceFile* f, pugi::xml_node n, Props& p) {
    Transform t = getTransform(f, p, "to_world");
    DeltaLight l;
    l.point = true;
    l.v = t.point(Vec3f(0.f));
    l.axis = unitDirection(f, n, t.vector(Vec3f(0.f, 0.f, 1.f)), "a 'spot' emitter's to_world loses its axis");
    l.value = getColor(f, p, "intensity", Color(1.f));
    float cutoff = getFloat(f, p, "cutoff_angle", 20.f);
    float beam = getFloat(f, p, "beam_width", cutoff * 0.75f);
    if (!(cutoff > 0.f && cutoff <= 180.f)) fail(f, n, "cutoff_angle must be in (0, 180] degrees");
    if (!(beam > 0.f && beam <= cutoff)) fail(f, n, "beam_width must be in (0, cutoff_angle] degrees");
    setSpotCone(l, cutoff * kPi / 180.f, beam * kPi / 180.f);
    return l;
  }

  // An area emitter marks its shape emissive; envmap and constant become the scene's environment.
  void emitter(const SourceFile* f, pugi::xml_node n, ShapeEntry* shape) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    Props p = collectProps(f, n);
    int radianceTexture = -1;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element || isPropTag(c.name())) continue;
      const std::string tag = c.name(), name = c.attribute("name").as_string();
      // An area light's radiance may be a texture (nested or a <ref>), read where light leaves.
      if (type == "area" && name == "radiance" && (tag == "texture" || tag == "ref")) {
        if (radianceTexture >= 0 || p.count("radiance")) fail(f, c, "the area emitter's radiance is given twice");
        radianceTexture = textureChild(f, c);
        continue;
      }
      if (tag != "texture") fail(f, c, fmt::format("unexpected <{}> in <emitter>", tag));
      warnOnce(fmt::format("{}:{}: a texture for '{}' of emitter '{}' is not supported; the property keeps its default",
                           f->path, f->lineOf(c.offset_debug()), name, type));
    }
    if (type == "area") {
      if (!shape) fail(f, n, "an 'area' emitter must be inside a <shape>");
      shape->emissive = true;
      shape->radiance = getColor(f, p, "radiance", Color(1.f));
      if (radianceTexture >= 0) {
        // The texture's mean stands for the light's power when next-event estimation and the
        // photon pass choose among lights.
        shape->radianceTexture = radianceTexture;
        shape->radiance = textureMean(scene_.textures[size_t(radianceTexture)]);
      }
    } else if (shape) {
      fail(f, n, fmt::format("only 'area' emitters can be inside a <shape>, not '{}'", type));
    } else if (type == "envmap" || type == "constant") {
      if (scene_.env) fail(f, n, "the scene already has an environment emitter");
      EnvironmentMapOptions o;
      if (type == "envmap") {
        std::string file = getString(f, p, "filename", "");
        if (file.empty()) fail(f, n, "envmap needs a 'filename'");
        fs::path path = fs::path(f->path).parent_path() / file;
        o.scale = getFloat(f, p, "scale", 1.f);
        if (o.scale < 0.f) fail(f, n, "envmap scale must not be negative");
        o.toWorld = getTransform(f, p, "to_world");
        o.misCompensation = getBool(f, p, "mis_compensation", false);
        std::string filter = getString(f, p, "filter_type", "bilinear");
        if (filter != "bilinear" && filter != "nearest") fail(f, n, "filter_type must be bilinear or nearest");
        o.bilinear = filter == "bilinear";
        // envgi's own: a square light probe, resampled to lat-long as it is read.
        std::string layout = getString(f, p, "layout", "latlong");
        if (layout != "latlong" && layout != "angular" && layout != "mirrorball" && layout != "cross")
          fail(f, n, "layout must be latlong, angular, mirrorball or cross, not '" + layout + "'");
        reportUnused(f, p, "emitter", type);  // a misspelt property before a large map's load, not after
        try {
          scene_.env = std::make_unique<EnvironmentMap>(EnvironmentMap::loadLayout(path.string(), layout, o));
        } catch (const std::runtime_error& e) {
          rethrowAt(f, n, e);
        }
      } else {
        Color L = getColor(f, p, "radiance", Color(1.f));
        scene_.env = std::make_unique<EnvironmentMap>(EnvironmentMap::constant(L, o));
      }
    } else if (type == "directional" || type == "point") {
      scene_.deltaLights.push_back(deltaLight(f, n, type, p));
    } else if (type == "spot") {
      scene_.deltaLights.push_back(spotLight(f, n, p));
    } else {
      warnOnce(fmt::format("{}:{}: emitter type '{}' is not supported and was ignored", f->path,
                           f->lineOf(n.offset_debug()), type));
      return;
    }
    reportUnused(f, p, "emitter", type);
  }

  int bsdf(const SourceFile* f, pugi::xml_node n) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    Props p = collectProps(f, n);
    Bsdf b;
    float extIor = 1.000277f;
    if (type == "twosided") {
      pugi::xml_node inner;
      for (pugi::xml_node c : n.children())
        if (c.type() == pugi::node_element && std::string(c.name()) == "bsdf") {
          if (inner) fail(f, c, "twosided with two different BSDFs is not supported");
          inner = c;
        } else if (c.type() == pugi::node_element && std::string(c.name()) == "ref") {
          checkAttrs(f, c, {"id", "name"});
          auto it = bsdfIds_.find(attr(f, c, "id"));
          if (it == bsdfIds_.end()) fail(f, c, fmt::format("unknown BSDF id '{}'", attr(f, c, "id")));
          int copy = copyBsdf(it->second.index);
          forEachChoice(copy, [](Bsdf& b) { b.twoSided = true; });
          return copy;
        }
      if (!inner) fail(f, n, "twosided needs a nested <bsdf>");
      int id = bsdf(f, inner);
      forEachChoice(id, [](Bsdf& b) { b.twoSided = true; });
      return id;
    }
    if (type == "normalmap" || type == "bumpmap") return normalMap(f, n, p, type == "bumpmap");
    if (type == "mask") return mask(f, n, p);
    if (type == "blendbsdf") return blend(f, n, p);
    // Textured properties, by name: nested <texture name=...> or <ref id=... name=...>.
    std::map<std::string, std::pair<int, pugi::xml_node>> textures;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (tag != "texture" && tag != "ref") continue;
      const int index = textureChild(f, c);
      std::string name = attr(f, c, "name");
      if (p.count(name) || textures.count(name)) fail(f, c, fmt::format("property '{}' given twice", name));
      textures[name] = {index, c};
    }
    if (type == "diffuse") {
      b.type = BsdfType::Diffuse;
      b.reflectance = getColor(f, p, "reflectance", Color(0.5f));
    } else if (type == "conductor" || type == "roughconductor") {
      b.type = type == "conductor" ? BsdfType::Conductor : BsdfType::RoughConductor;
      std::string material = getString(f, p, "material", "none");
      try {
        conductorPreset(material, &b.eta, &b.k, &b.perfectMirror);
      } catch (const std::runtime_error& e) {
        rethrowAt(f, n, e);
      }
      if (p.count("eta") || p.count("k")) {
        b.eta = getColor(f, p, "eta", Color(0.f));
        b.k = getColor(f, p, "k", Color(1.f));
        b.perfectMirror = false;
      }
      b.specularReflectance = getColor(f, p, "specular_reflectance", Color(1.f));
      if (type == "roughconductor") roughness(f, n, p, textures, b, type);
    } else if (type == "dielectric" || type == "thindielectric" || type == "roughdielectric") {
      b.type = type == "dielectric" ? BsdfType::Dielectric
               : type == "thindielectric" ? BsdfType::ThinDielectric : BsdfType::RoughDielectric;
      b.ior = interfaceIor(f, n, p, 1.5046f, extIor);
      b.specularReflectance = getColor(f, p, "specular_reflectance", Color(1.f));
      b.specularTransmittance = getColor(f, p, "specular_transmittance", Color(1.f));
      if (type == "roughdielectric") roughness(f, n, p, textures, b, type);
    } else if (type == "plastic" || type == "roughplastic") {
      b.type = type == "plastic" ? BsdfType::Plastic : BsdfType::RoughPlastic;
      b.ior = interfaceIor(f, n, p, 1.49f, extIor);
      b.reflectance = getColor(f, p, "diffuse_reflectance", Color(0.5f));
      b.specularReflectance = getColor(f, p, "specular_reflectance", Color(1.f));
      b.nonlinear = getBool(f, p, "nonlinear", false);
      if (type == "roughplastic") roughness(f, n, p, textures, b, type);
      finishPlastic(b);
    } else if (type == "principled") {
      principled(f, n, p, b);
    } else {
      fail(f, n, fmt::format("unknown BSDF type '{}' (diffuse, conductor, roughconductor, dielectric, thindielectric, "
                             "roughdielectric, plastic, roughplastic, principled, twosided, normalmap, bumpmap, mask, blendbsdf)",
                             type));
    }
    for (const auto& [name, tex] : textures) {
      int* slot = textureSlot(b, name);
      if (!slot) {
        warnOnce(fmt::format("{}:{}: a texture for '{}' of bsdf '{}' is not supported; the property keeps its default",
                             f->path, f->lineOf(tex.second.offset_debug()), name, type));
        continue;
      }
      *slot = tex.first;
    }
    if ((b.type == BsdfType::Plastic || b.type == BsdfType::RoughPlastic) &&
        (b.reflectanceTexture >= 0 || b.specularReflectanceTexture >= 0)) {
      // The coat's share of samples from the textures' mean colours, as Mitsuba's plastic does.
      Bsdf means = b;
      if (b.reflectanceTexture >= 0) means.reflectance = textureMean(scene_.textures[size_t(b.reflectanceTexture)]);
      if (b.specularReflectanceTexture >= 0)
        means.specularReflectance = textureMean(scene_.textures[size_t(b.specularReflectanceTexture)]);
      finishPlastic(means);
      b.specularSamplingWeight = means.specularSamplingWeight;
    }
    for (pugi::xml_node c : n.children())
      if (c.type() == pugi::node_element && !isPropTag(c.name()) && std::string(c.name()) != "texture" &&
          std::string(c.name()) != "ref")
        fail(f, c, fmt::format("unexpected <{}> in <bsdf>", c.name()));
    reportUnused(f, p, "bsdf", type);
    scene_.bsdfs.push_back(b);
    return int(scene_.bsdfs.size() - 1);
  }

  // Mitsuba 3's principled BSDF, its properties as Mitsuba reads them; a value outside its range
  // is an error here (Mitsuba takes it and renders something unphysical).
  void principled(const SourceFile* f, pugi::xml_node n, Props& p, Bsdf& b) {
    b.type = BsdfType::Principled;
    b.reflectance = getColor(f, p, "base_color", Color(0.5f));
    PrincipledParams& q = b.principled;
    auto unit = [&](const char* name, float def) {
      float v = getFloat(f, p, name, def);
      if (!(v >= 0.f && v <= 1.f)) fail(f, n, fmt::format("principled '{}' must lie in [0, 1] (got {})", name, v));
      return v;
    };
    q.roughness = unit("roughness", 0.5f);
    q.anisotropic = unit("anisotropic", 0.f);
    q.metallic = unit("metallic", 0.f);
    q.specTrans = unit("spec_trans", 0.f);
    q.specTint = unit("spec_tint", 0.f);
    q.sheen = unit("sheen", 0.f);
    q.sheenTint = unit("sheen_tint", 0.f);
    q.flatness = unit("flatness", 0.f);
    q.clearcoat = unit("clearcoat", 0.f);
    q.clearcoatGloss = unit("clearcoat_gloss", 0.f);
    auto rate = [&](const char* name) {
      float v = getFloat(f, p, name, 1.f);
      if (!(v >= 0.f && v < INFINITY)) fail(f, n, fmt::format("principled '{}' must be finite and >= 0 (got {})", name, v));
      return v;
    };
    q.specularRate = rate("main_specular_sampling_rate");
    q.clearcoatRate = rate("clearcoat_sampling_rate");
    q.diffuseRate = rate("diffuse_reflectance_sampling_rate");
    if (q.specularRate + q.clearcoatRate + q.diffuseRate <= 0.f) fail(f, n, "principled: every sampling rate is 0");
    // Either eta or specular (the reflectance at normal incidence is 0.08 specular), as Mitsuba.
    if (p.count("eta") && p.count("specular")) fail(f, n, "principled takes 'eta' or 'specular', not both");
    if (p.count("eta")) {
      b.ior = getFloat(f, p, "eta", 1.5f);
      if (!(b.ior > 0.f && b.ior < INFINITY)) fail(f, n, fmt::format("principled 'eta' must be > 0 (got {})", b.ior));
      if (b.ior == 1.f && q.specTrans > 0.f) b.ior = 1.001f;  // Mitsuba's: glass of index 1 refracts nothing
    } else {
      float specular = getFloat(f, p, "specular", 0.5f);
      if (!(specular >= 0.f && specular < 12.5f))
        fail(f, n, fmt::format("principled 'specular' must lie in [0, 12.5) (got {})", specular));
      if (specular == 0.f && q.specTrans > 0.f) specular = 1e-3f;  // as Mitsuba
      b.ior = principledEtaFromSpecular(specular);
    }
  }

  // A copy of material `index` as a new entry, a blend's choices copied too (so that an adapter
  // may change the copy's materials without changing the original's).
  int copyBsdf(int index) {
    Bsdf b = scene_.bsdfs[size_t(index)];
    if (bsdfIsBlend(b)) {
      b.blend0 = copyBsdf(b.blend0);
      b.blend1 = copyBsdf(b.blend1);
    }
    scene_.bsdfs.push_back(b);
    return int(scene_.bsdfs.size() - 1);
  }
  // Calls fn on each material that material `index` may turn out to be at a hit: itself, or for a
  // blend the materials its choices may be (what twosided and the normal maps change).
  template <class Fn>
  void forEachChoice(int index, Fn&& fn) {
    Bsdf& b = scene_.bsdfs[size_t(index)];
    if (!bsdfIsBlend(b)) return fn(b);
    int b0 = b.blend0, b1 = b.blend1;  // fn may grow the vector
    forEachChoice(b0, fn);
    forEachChoice(b1, fn);
  }
  // Whether material `index` or any material a blend of it holds, at any depth, is masked.
  bool anyMasked(int index) const {
    const Bsdf& b = scene_.bsdfs[size_t(index)];
    return bsdfIsMasked(b) || (bsdfIsBlend(b) && (anyMasked(b.blend0) || anyMasked(b.blend1)));
  }
  int blendDepth(int index) const {
    const Bsdf& b = scene_.bsdfs[size_t(index)];
    return bsdfIsBlend(b) ? 1 + std::max(blendDepth(b.blend0), blendDepth(b.blend1)) : 0;
  }

  // An adapter's children (normalmap, bumpmap, mask; blendbsdf takes two): `count` nested BSDFs
  // (<bsdf> or a <ref> to one, copied) and textures (nested, or a <ref> named as one or to an id
  // only a texture has), each handed to onTexture(node, index). Returns the nested BSDFs' indices.
  template <class OnTexture>
  std::vector<int> adapterChildren(const SourceFile* f, pugi::xml_node n, const char* adapter, size_t count,
                                   OnTexture&& onTexture) {
    std::vector<int> inner;
    auto setInner = [&](pugi::xml_node c, int id) {
      if (inner.size() == count)
        fail(f, c, count == 1 ? fmt::format("{} takes one nested BSDF", adapter)
                              : fmt::format("{} takes {} nested BSDFs", adapter, count));
      inner.push_back(id);
    };
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (tag == "bsdf") {
        setInner(c, bsdf(f, c));
      } else if (tag == "texture") {
        onTexture(c, texture(f, c));
      } else if (tag == "ref") {
        checkAttrs(f, c, {"id", "name"});
        std::string id = attr(f, c, "id");
        auto b = bsdfIds_.find(id);
        auto t = textureIds_.find(id);
        if (t != textureIds_.end() && (b == bsdfIds_.end() || c.attribute("name"))) {
          onTexture(c, t->second.index);
        } else if (b != bsdfIds_.end()) {
          setInner(c, copyBsdf(b->second.index));
        } else {
          fail(f, c, fmt::format("unknown BSDF or texture id '{}'", id));
        }
      } else if (!isPropTag(tag)) {
        fail(f, c, fmt::format("unexpected <{}> in <bsdf>", tag));
      }
    }
    if (inner.size() < count)
      fail(f, n, count == 1 ? fmt::format("{} needs a nested <bsdf>", adapter)
                            : fmt::format("{} needs {} nested BSDFs", adapter, count));
    return inner;
  }

  // Mitsuba's blendbsdf: two nested BSDFs, in the order given, and `weight` (0.5 unless given),
  // a number in [0, 1] or a texture read as its luminance: the second BSDF's share.
  int blend(const SourceFile* f, pugi::xml_node n, Props& p) {
    int map = -1;
    std::vector<int> inner = adapterChildren(f, n, "blendbsdf", 2, [&](pugi::xml_node c, int id) {
      std::string name = c.attribute("name").as_string();
      if (name != "weight") fail(f, c, fmt::format("blendbsdf has no texture property '{}' (its texture is named 'weight')", name));
      if (map >= 0 || p.count("weight")) fail(f, c, "property 'weight' given twice");
      map = id;
    });
    Bsdf b;
    b.blend0 = inner[0];
    b.blend1 = inner[1];
    if (map >= 0) {
      b.blendWeightTexture = map;
    } else {
      b.blendWeight = getFloat(f, p, "weight", 0.5f);
      if (!(b.blendWeight >= 0.f && b.blendWeight <= 1.f))
        fail(f, n, fmt::format("blendbsdf's weight must be within [0, 1], not {}", b.blendWeight));
    }
    // The tracers ask the material a ray hits, before any choice, whether the ray stops there.
    for (int i : inner)
      if (anyMasked(i)) fail(f, n, "a mask inside a blendbsdf is not supported (put the mask around the blendbsdf)");
    reportUnused(f, p, "bsdf", "blendbsdf");
    scene_.bsdfs.push_back(b);
    int id = int(scene_.bsdfs.size() - 1);
    if (blendDepth(id) > kMaxBlendDepth) fail(f, n, fmt::format("blendbsdfs nest at most {} deep", kMaxBlendDepth));
    return id;
  }

  // Mitsuba's mask: a nested BSDF and its `opacity` (0.5 unless given), a number or a texture
  // read as its luminance, clamped to [0, 1].
  int mask(const SourceFile* f, pugi::xml_node n, Props& p) {
    int map = -1;
    int inner = adapterChildren(f, n, "mask", 1, [&](pugi::xml_node c, int id) {
      std::string name = c.attribute("name").as_string();
      if (name != "opacity") fail(f, c, fmt::format("mask has no texture property '{}' (its texture is named 'opacity')", name));
      if (map >= 0 || p.count("opacity")) fail(f, c, "property 'opacity' given twice");
      map = id;
    })[0];
    Bsdf& b = scene_.bsdfs[size_t(inner)];
    if (bsdfIsMasked(b)) fail(f, n, "a mask around a mask is not supported");
    if (map >= 0) {
      b.opacityTexture = map;
      b.opacity = 0.f;  // read from the texture at each hit
    } else {
      float a = getFloat(f, p, "opacity", 0.5f);
      if (!(a >= 0.f && a <= 1.f)) fail(f, n, fmt::format("mask's opacity must be within [0, 1], not {}", a));
      b.opacity = a;
    }
    reportUnused(f, p, "bsdf", "mask");
    return inner;
  }

  // Mitsuba's normalmap and bumpmap adapters: one nested BSDF and a texture (named `normalmap`;
  // bumpmap's may have any name). The result is the nested BSDF with the map attached (a copy
  // where referenced).
  int normalMap(const SourceFile* f, pugi::xml_node n, Props& p, bool bump) {
    const char* adapter = bump ? "bumpmap" : "normalmap";
    int map = -1;
    int inner = adapterChildren(f, n, adapter, 1, [&](pugi::xml_node c, int id) {
      std::string name = c.attribute("name").as_string();
      if (bump) {
        if (map >= 0) fail(f, c, "bumpmap takes one texture");
      } else {
        if (name != "normalmap")
          fail(f, c, fmt::format("normalmap has no texture property '{}' (its texture is named 'normalmap')", name));
        if (map >= 0) fail(f, c, "property 'normalmap' given twice");
      }
      map = id;
    })[0];
    if (map < 0) fail(f, n, bump ? "bumpmap needs a nested texture (its height)" : "normalmap needs a texture named 'normalmap'");
    const float bumpScale = bump ? getFloat(f, p, "scale", 1.f) : 1.f;
    if (!std::isfinite(bumpScale)) fail(f, n, "bumpmap's scale must be finite");
    // Mitsuba 3.9 gives both adapters the same two flags (its perturbed_bsdf).
    const bool flip = getBool(f, p, "flip_invalid_normals", true), shadowing = getBool(f, p, "use_shadowing_function", true);
    // Around a blend, each material it may choose is evaluated in the same tilted frame.
    forEachChoice(inner, [&](Bsdf& b) {
      if (bsdfIsNormalMapped(b)) fail(f, n, fmt::format("a {} around a normalmap or bumpmap is not supported", adapter));
      if (bump) {
        b.bumpTexture = map;
        b.bumpScale = bumpScale;
      } else {
        b.normalMapTexture = map;
      }
      b.flipInvalidNormals = flip;
      b.bumpShadowing = shadowing;
    });
    reportUnused(f, p, "bsdf", adapter);
    return inner;
  }

  // Where a texture for property `name` goes in b (the colours, and the roughness of the rough
  // BSDFs); null for a property envgi reads as a constant only.
  static int* textureSlot(Bsdf& b, const std::string& name) {
    if (b.type == BsdfType::Principled) {
      if (name == "base_color") return &b.reflectanceTexture;
      if (name == "roughness") return &b.roughnessTexture;
      if (name == "metallic") return &b.metallicTexture;
      return nullptr;
    }
    bool plastic = b.type == BsdfType::Plastic || b.type == BsdfType::RoughPlastic;
    if ((b.type == BsdfType::Diffuse && name == "reflectance") || (plastic && name == "diffuse_reflectance"))
      return &b.reflectanceTexture;
    if (b.type != BsdfType::Diffuse && name == "specular_reflectance") return &b.specularReflectanceTexture;
    if (bsdfTransmits(b) && name == "specular_transmittance") return &b.specularTransmittanceTexture;
    bool rough = b.type == BsdfType::RoughConductor || b.type == BsdfType::RoughDielectric || b.type == BsdfType::RoughPlastic;
    if (rough && name == "alpha") return &b.alphaTexture;
    // alpha_u is the anisotropic form's alpha; roughplastic has no anisotropic form (Mitsuba's).
    bool anisotropicForm = b.type == BsdfType::RoughConductor || b.type == BsdfType::RoughDielectric;
    if (anisotropicForm && name == "alpha_u") return &b.alphaTexture;
    if (anisotropicForm && name == "alpha_v") return &b.alphaVTexture;
    return nullptr;
  }

  static Color textureMean(const Texture& t) {
    if (t.params.type == TextureType::Checkerboard) return (t.params.color0 + t.params.color1) * 0.5f;
    double sum[3] = {0, 0, 0};
    for (const Color& c : t.texels)
      for (int k = 0; k < 3; ++k) sum[k] += c[k];
    double n = double(std::max<size_t>(t.texels.size(), 1));
    return Color(float(sum[0] / n), float(sum[1] / n), float(sum[2] / n));
  }

  // A texture given to a property: a nested <texture> (read here) or a <ref> to a named one;
  // the index into scene_.textures.
  int textureChild(const SourceFile* f, pugi::xml_node c) {
    if (std::string(c.name()) == "texture") return texture(f, c);
    checkAttrs(f, c, {"id", "name"});
    auto it = textureIds_.find(attr(f, c, "id"));
    if (it == textureIds_.end()) fail(f, c, fmt::format("unknown texture id '{}'", attr(f, c, "id")));
    return it->second.index;
  }

  // Mitsuba's bitmap and checkerboard textures; returns the index into scene_.textures.
  int texture(const SourceFile* f, pugi::xml_node n) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    Props p = collectProps(f, n);
    Texture t;
    TextureView& v = t.params;
    if (type == "bitmap") {
      v.type = TextureType::Bitmap;
      std::string file = getString(f, p, "filename", "");
      if (file.empty()) fail(f, n, "bitmap needs a 'filename'");
      std::string filter = getString(f, p, "filter_type", "bilinear");
      if (filter != "bilinear" && filter != "nearest") fail(f, n, "filter_type must be bilinear or nearest");
      v.bilinear = filter == "bilinear";
      std::string wrap = getString(f, p, "wrap_mode", "repeat");
      if (wrap == "repeat") v.wrap = TextureWrap::Repeat;
      else if (wrap == "mirror") v.wrap = TextureWrap::Mirror;
      else if (wrap == "clamp") v.wrap = TextureWrap::Clamp;
      else fail(f, n, fmt::format("wrap_mode must be repeat, mirror or clamp, not '{}'", wrap));
      bool raw = getBool(f, p, "raw", false);
      fs::path path = fs::path(f->path).parent_path() / file;
      Image img;
      try {
        img = loadImage(path.string(), !raw);
      } catch (const std::runtime_error& e) {
        rethrowAt(f, n, e);
      }
      // A texel that is NaN, infinite or negative would poison every path that reads it.
      for (float x : img.rgb)
        if (!(x >= 0.f && x <= 3.4e38f))
          fail(f, n, fmt::format("texture '{}' has a negative, NaN or infinite texel", path.string()));
      v.width = img.width;
      v.height = img.height;
      t.texels.resize(size_t(img.width) * img.height);
      for (size_t i = 0; i < t.texels.size(); ++i) t.texels[i] = {img.rgb[3 * i], img.rgb[3 * i + 1], img.rgb[3 * i + 2]};
    } else if (type == "checkerboard") {
      v.type = TextureType::Checkerboard;
      v.color0 = getColor(f, p, "color0", Color(0.4f));
      v.color1 = getColor(f, p, "color1", Color(0.2f));
    } else {
      fail(f, n, fmt::format("unknown texture type '{}' (bitmap, checkerboard)", type));
    }
    // to_uv acts on (u, v, 0, 1): its upper-left 2x2 and the translation's x and y.
    Matrix4 m = getTransform(f, p, "to_uv").mat;
    float toUv[6] = {m.m[0][0], m.m[0][1], m.m[0][3], m.m[1][0], m.m[1][1], m.m[1][3]};
    std::copy(toUv, toUv + 6, v.toUv);
    for (pugi::xml_node c : n.children())
      if (c.type() == pugi::node_element && !isPropTag(c.name()))
        fail(f, c, fmt::format("unexpected <{}> in <texture> (a texture's colours are constants)", c.name()));
    reportUnused(f, p, "texture", type);
    scene_.textures.push_back(std::move(t));
    return int(scene_.textures.size() - 1);
  }

  void roughness(const SourceFile* f, pugi::xml_node n, Props& p,
                 const std::map<std::string, std::pair<int, pugi::xml_node>>& textures, Bsdf& b,
                 const std::string& type) {
    // Mitsuba's default, for all three rough BSDFs, is Beckmann.
    std::string dist = getString(f, p, "distribution", "beckmann");
    if (dist == "beckmann") b.distribution = MicrofacetType::Beckmann;
    else if (dist == "ggx") b.distribution = MicrofacetType::GGX;
    else fail(f, n, fmt::format("{} distribution must be beckmann or ggx, not '{}'", type, dist));
    auto checked = [&](const char* name) {
      float a = getFloat(f, p, name, 0.1f);
      if (!(a > 0.f && a <= kMaxAlpha)) fail(f, n, fmt::format("{} must be in (0, 4]", name));
      return std::max(a, kMinAlpha);
    };
    // Anisotropic conductors and dielectrics (Mitsuba's alpha_u, alpha_v: along dp/du, dp/dv),
    // each a value or a texture (the texture then replaces the value at each hit).
    auto given = [&](const char* name) { return p.count(name) > 0 || textures.count(name) > 0; };
    if (type != "roughplastic" && (given("alpha_u") || given("alpha_v"))) {
      if (given("alpha")) fail(f, n, "give either alpha or alpha_u and alpha_v, not both");
      b.alpha = checked("alpha_u");
      b.alphaV = checked("alpha_v");
    } else {
      b.alpha = checked("alpha");
    }
    find(p, "sample_visible");
  }

  // A shape as read, before it is placed: its geometry in its own space, its to_world and its
  // material, so that a shape group's meshes load once however many instances place them.
  struct ShapeTemplate {
    ShapeEntry entry;  // the material and area light; index is set where the shape is placed
    bool isSphere = false;
    Vec3f center;
    float radius = 1.f;
    TriangleMesh mesh;  // untransformed
    Transform toWorld;
    bool flip = false, faceNormals = false, fromFile = false;
  };
  struct ShapeGroup {
    std::vector<ShapeTemplate> shapes;
    std::vector<int> prototypes;  // each mesh's index in Scene::prototypes once an instance placed it, else -1
    std::string where;  // "file:line" of its definition, for a duplicate's error
  };
  std::map<std::string, ShapeGroup> groups_;
  size_t instances_ = 0, instancedShapes_ = 0;  // for the log
  size_t prototypeTriangles() const {
    size_t n = 0;
    for (const TriangleMesh& m : scene_.prototypes) n += m.triangleCount();
    return n;
  }
  size_t instancedTriangles() const {
    size_t n = 0;
    for (const MeshInstance& i : scene_.instances) n += scene_.prototypes[size_t(i.prototype)].triangleCount();
    return n;
  }

  // A top-level <shape>: a shape group is kept for its instances, an instance places its group,
  // anything else goes into the scene as it is.
  void shape(const SourceFile* f, pugi::xml_node n) {
    checkAttrs(f, n, {"type", "id", "name"});
    std::string type = attr(f, n, "type");
    if (type == "shapegroup") {
      std::string id = attr(f, n, "id", false);
      if (id.empty()) fail(f, n, "a shapegroup needs an id, which its instances refer to");
      std::string where = fmt::format("{}:{}", f->path, f->lineOf(n.offset_debug()));
      if (auto it = groups_.find(id); it != groups_.end())
        fail(f, n, fmt::format("duplicate id '{}' (first defined at {})", id, it->second.where));
      if (bsdfIds_.count(id) || textureIds_.count(id)) fail(f, n, fmt::format("duplicate id '{}'", id));
      ShapeGroup g = shapeGroup(f, n);
      g.where = where;
      groups_[id] = std::move(g);
    } else if (type == "instance") {
      instance(f, n);
    } else {
      placeShape(readShape(f, n, type), Transform{});  // moved: a plain shape's mesh is not copied
    }
  }

  // Mitsuba's shapegroup: shapes that appear only where an instance places them. As in Mitsuba,
  // a group holds no emitter, no other group and no instance.
  ShapeGroup shapeGroup(const SourceFile* f, pugi::xml_node n) {
    Props p = collectProps(f, n);
    reportUnused(f, p, "shape", "shapegroup");
    ShapeGroup g;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (isPropTag(tag)) continue;
      if (tag != "shape") fail(f, c, fmt::format("unexpected <{}> in a shapegroup (only <shape>)", tag));
      checkAttrs(f, c, {"type", "id", "name"});
      std::string type = attr(f, c, "type");
      if (type == "shapegroup") fail(f, c, "a shapegroup inside a shapegroup is not permitted (as in Mitsuba)");
      if (type == "instance") fail(f, c, "an instance inside a shapegroup is not permitted (as in Mitsuba)");
      g.shapes.push_back(readShape(f, c, type));
      if (g.shapes.back().entry.emissive)
        fail(f, c, "a shape in a shapegroup cannot be an area emitter (Mitsuba does not instance emitters)");
    }
    return g;
  }

  // Mitsuba's instance: its group's shapes placed under its to_world. A mesh is placed as a
  // MeshInstance of the group's mesh (made once, with the shape's own to_world, normals and
  // flip applied), which every instance of the group shares; a sphere as a sphere of its own.
  void instance(const SourceFile* f, pugi::xml_node n) {
    Props p = collectProps(f, n);
    Transform toWorld = getTransform(f, p, "to_world");
    ShapeGroup* group = nullptr;
    ShapeGroup inlineGroup;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (isPropTag(tag)) continue;
      if (group) fail(f, c, "an instance refers to one shapegroup");
      if (tag == "ref") {
        checkAttrs(f, c, {"id", "name"});
        std::string id = attr(f, c, "id");
        auto it = groups_.find(id);
        if (it == groups_.end())
          fail(f, c,
               bsdfIds_.count(id) || textureIds_.count(id)
                   ? fmt::format("'{}' is not a shapegroup: an instance refers to a shapegroup", id)
                   : fmt::format("unknown shapegroup id '{}' (a shapegroup is defined before its instances)", id));
        group = &it->second;
      } else if (tag == "shape" && std::string(c.attribute("type").as_string()) == "shapegroup") {
        checkAttrs(f, c, {"type", "id", "name"});
        inlineGroup = shapeGroup(f, c);
        group = &inlineGroup;
      } else {
        fail(f, c, fmt::format("unexpected <{}> in an instance (a <ref> to a shapegroup)", tag));
      }
    }
    if (!group) fail(f, n, "an instance needs a <ref id=\"...\"/> to a shapegroup");
    reportUnused(f, p, "shape", "instance");
    group->prototypes.resize(group->shapes.size(), -1);
    for (size_t i = 0; i < group->shapes.size(); ++i) {
      const ShapeTemplate& t = group->shapes[i];
      if (t.isSphere) {
        placeShape(t, toWorld);
        continue;
      }
      int& proto = group->prototypes[i];
      if (proto < 0) {
        proto = int(scene_.prototypes.size());
        scene_.prototypes.push_back(placedMesh(t, Transform{}));
      }
      ShapeEntry entry = t.entry;
      entry.isInstance = true;
      entry.index = scene_.instances.size();
      scene_.instances.push_back({proto, toWorld});
      scene_.shapes.push_back(entry);
    }
    ++instances_;
    instancedShapes_ += group->shapes.size();
  }

  ShapeTemplate readShape(const SourceFile* f, pugi::xml_node n, const std::string& type) {
    Props p = collectProps(f, n);
    ShapeTemplate t;
    t.toWorld = getTransform(f, p, "to_world");
    t.flip = getBool(f, p, "flip_normals", false);
    if (type == "sphere") {
      t.center = getPoint(f, p, "center", Vec3f(0.f));
      t.radius = getFloat(f, p, "radius", 1.f);
      if (!(t.radius > 0.f)) fail(f, n, "sphere radius must be positive");
      t.isSphere = true;
    } else {
      t.fromFile = type == "ply" || type == "obj" || type == "serialized";
      t.faceNormals = getBool(f, p, "face_normals", false);
      // Mitsuba's ply and obj loaders flip v by default: files give v up the image, bitmaps store
      // rows down. Its serialized loader keeps v as stored.
      bool flipUv = (type == "ply" || type == "obj") && getBool(f, p, "flip_tex_coords", true);
      const int shapeIndex = type == "serialized" ? getInt(f, p, "shape_index", 0) : 0;
      try {
        if (t.fromFile) {
          std::string file = getString(f, p, "filename", "");
          if (file.empty()) fail(f, n, type + " shape needs a 'filename'");
          reportUnused(f, p, "shape", type);  // a misspelt property before a large mesh's load, not after
          fs::path path = fs::path(f->path).parent_path() / file;
          if (!fs::exists(path)) fail(f, n, fmt::format("mesh file '{}' does not exist", path.string()));
          if (type == "serialized") {
            bool fileFaceNormals = false;
            t.mesh = loadSerialized(path.string(), shapeIndex, &fileFaceNormals);
            t.faceNormals = t.faceNormals || fileFaceNormals;  // the file's flag means face_normals
          } else {
            t.mesh = type == "ply" ? loadPly(path.string()) : loadObj(path.string());
          }
        } else if (type == "rectangle") {
          t.mesh = makeRectangle();
        } else if (type == "cube") {
          t.mesh = makeCube();
        } else if (type == "disk") {
          t.mesh = makeDisk();
        } else if (type == "cylinder") {
          t.mesh = makeCylinder(getPoint(f, p, "p0", Vec3f(0.f)), getPoint(f, p, "p1", Vec3f(0.f, 0.f, 1.f)),
                                getFloat(f, p, "radius", 1.f));
        } else {
          fail(f, n,
               fmt::format("unknown shape type '{}' (ply, obj, serialized, sphere, rectangle, cube, disk, cylinder, "
                           "shapegroup, instance)",
                           type));
        }
      } catch (const std::runtime_error& e) {
        rethrowAt(f, n, e);
      }
      if (flipUv)
        for (Vec2f& uv : t.mesh.uvs) uv.y = 1.f - uv.y;
    }
    ShapeEntry& entry = t.entry;
    entry.bsdf = -1;
    for (pugi::xml_node c : n.children()) {
      if (c.type() != pugi::node_element) continue;
      std::string tag = c.name();
      if (tag == "bsdf") {
        if (entry.bsdf >= 0) fail(f, c, "a shape has at most one BSDF");
        entry.bsdf = bsdf(f, c);
      } else if (tag == "medium" || tag == "phase" ||
                 (tag == "ref" && (std::string(c.attribute("name").as_string()) == "interior" ||
                                   std::string(c.attribute("name").as_string()) == "exterior"))) {
        ignoreMedium(f, c);
      } else if (tag == "ref") {
        checkAttrs(f, c, {"id", "name"});
        auto it = bsdfIds_.find(attr(f, c, "id"));
        if (it == bsdfIds_.end()) fail(f, c, fmt::format("unknown BSDF id '{}'", attr(f, c, "id")));
        if (entry.bsdf >= 0) fail(f, c, "a shape has at most one BSDF");
        entry.bsdf = it->second.index;
      } else if (tag == "emitter") {
        emitter(f, c, &entry);
      } else if (!isPropTag(tag)) {
        fail(f, c, fmt::format("unexpected <{}> in <shape>", tag));
      }
    }
    if (entry.bsdf < 0) {
      // Mitsuba's default: diffuse, reflectance 0.5, or black on an area light (a grey light
      // facing a wall reflected 4.8% more light into the Cornell box than Mitsuba's).
      Bsdf b;
      if (entry.emissive) b.reflectance = Color(0.f);
      scene_.bsdfs.push_back(b);
      entry.bsdf = int(scene_.bsdfs.size() - 1);
    }
    // A masked light would be seen with the chance of its opacity while next-event estimation
    // reached all of it.
    if (entry.emissive && bsdfIsMasked(scene_.bsdfs[size_t(entry.bsdf)]))
      fail(f, n, "an area emitter's shape cannot have a mask BSDF");
    reportUnused(f, p, "shape", type);
    return t;
  }

  // Puts a shape into the scene under outer (an instance's to_world; identity for a plain shape):
  // the same as a shape whose to_world is outer times its own. By value: an instance passes a
  // copy of its group's shape, a plain shape its own.
  void placeShape(ShapeTemplate t, const Transform& outer) {
    const Transform toWorld = outer * t.toWorld;
    ShapeEntry entry = t.entry;
    if (t.isSphere) {
      Sphere s;
      s.center = toWorld.point(t.center);
      s.radius = t.radius * length(toWorld.vector(Vec3f(1.f, 0.f, 0.f)));
      s.axes = {normalize(toWorld.vector(Vec3f(1.f, 0.f, 0.f))), normalize(toWorld.vector(Vec3f(0.f, 1.f, 0.f))),
                normalize(toWorld.vector(Vec3f(0.f, 0.f, 1.f)))};
      s.flipNormals = t.flip;
      entry.isSphere = true;
      entry.index = scene_.spheres.size();
      scene_.spheres.push_back(s);
    } else {
      entry.index = scene_.meshes.size();
      scene_.meshes.push_back(placedMesh(std::move(t), outer));
    }
    scene_.shapes.push_back(entry);
  }

  // A mesh shape's triangles under outer times its own to_world, with its normals as the file
  // asks (computed where it has none) and flipped where it asks.
  static TriangleMesh placedMesh(ShapeTemplate t, const Transform& outer) {
    TriangleMesh mesh = std::move(t.mesh);
    mesh.transform(outer * t.toWorld);
    if (t.faceNormals) mesh.normals.clear();
    else if (mesh.normals.empty() && t.fromFile) mesh.computeVertexNormals();
    if (t.flip) {
      // Mitsuba flips the normals; reversing the winding keeps geometric and shading normals together.
      for (size_t i = 0; i < mesh.indices.size(); i += 3) std::swap(mesh.indices[i + 1], mesh.indices[i + 2]);
      for (Vec3f& nn : mesh.normals) nn = -nn;
    }
    return mesh;
  }
};

}  // namespace

void loadScene(const std::string& path, const std::map<std::string, std::string>& defines, Scene& scene) {
  Loader loader(scene, defines);
  loader.loadFile(path, 0);
  loader.finish();
  scene.sourcePath = path;
  scene.finalize();
}

void loadSceneString(const std::string& xml, const std::map<std::string, std::string>& defines, Scene& scene) {
  Loader loader(scene, defines);
  loader.loadText(kSceneStringName, xml, 0);
  loader.finish();
  scene.finalize();
}

}  // namespace envgi
