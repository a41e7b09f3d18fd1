// Minimal binary serialisation for results passed back from worker processes (parallel.h).
// Same binary, same machine: raw native encoding, no versioning.
#pragma once

#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace sbot::calib {

class Writer {
 public:
  template <class T>
  void raw(const T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "raw() needs a trivially copyable type");
    buf_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void bytes(const char* p, std::size_t n) { buf_.append(p, n); }
  const std::string& str() const { return buf_; }

 private:
  std::string buf_;
};

class Reader {
 public:
  explicit Reader(const std::string& s) : p_(s.data()), end_(s.data() + s.size()) {}
  template <class T>
  void raw(T& v) {
    need(sizeof(T));
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
  }
  void bytes(char* out, std::size_t n) {
    need(n);
    std::memcpy(out, p_, n);
    p_ += n;
  }

 private:
  void need(std::size_t n) {
    if (static_cast<std::size_t>(end_ - p_) < n) throw std::runtime_error("truncated worker result");
  }
  const char* p_;
  const char* end_;
};

// ---- primitives ----------------------------------------------------------------------------------
template <class T, typename std::enable_if<std::is_arithmetic<T>::value, int>::type = 0>
void save(Writer& w, T v) { w.raw(v); }
template <class T, typename std::enable_if<std::is_arithmetic<T>::value, int>::type = 0>
void load(Reader& r, T& v) { r.raw(v); }

inline void save(Writer& w, const std::string& s) {
  w.raw<std::uint64_t>(s.size());
  w.bytes(s.data(), s.size());
}
inline void load(Reader& r, std::string& s) {
  std::uint64_t n;
  r.raw(n);
  s.resize(n);
  if (n) r.bytes(&s[0], n);
}

// ---- containers ----------------------------------------------------------------------------------
template <class A, class B> void save(Writer& w, const std::pair<A, B>& p);
template <class A, class B> void load(Reader& r, std::pair<A, B>& p);
template <class T> void save(Writer& w, const std::vector<T>& v);
template <class T> void load(Reader& r, std::vector<T>& v);
template <class K, class V> void save(Writer& w, const std::map<K, V>& m);
template <class K, class V> void load(Reader& r, std::map<K, V>& m);

template <class A, class B>
void save(Writer& w, const std::pair<A, B>& p) {
  save(w, p.first);
  save(w, p.second);
}
template <class A, class B>
void load(Reader& r, std::pair<A, B>& p) {
  load(r, p.first);
  load(r, p.second);
}

template <class T>
void save(Writer& w, const std::vector<T>& v) {
  w.raw<std::uint64_t>(v.size());
  if constexpr (std::is_arithmetic<T>::value) {
    if (!v.empty()) w.bytes(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  } else {
    for (const auto& x : v) save(w, x);
  }
}
template <class T>
void load(Reader& r, std::vector<T>& v) {
  std::uint64_t n;
  r.raw(n);
  v.resize(n);
  if constexpr (std::is_arithmetic<T>::value) {
    if (n) r.bytes(reinterpret_cast<char*>(v.data()), n * sizeof(T));
  } else {
    for (auto& x : v) load(r, x);
  }
}

template <class K, class V>
void save(Writer& w, const std::map<K, V>& m) {
  w.raw<std::uint64_t>(m.size());
  for (const auto& [k, v] : m) {
    save(w, k);
    save(w, v);
  }
}
template <class K, class V>
void load(Reader& r, std::map<K, V>& m) {
  std::uint64_t n;
  r.raw(n);
  m.clear();
  for (std::uint64_t i = 0; i < n; ++i) {
    K k;
    V v;
    load(r, k);
    load(r, v);
    m.emplace(std::move(k), std::move(v));
  }
}

}  // namespace sbot::calib
