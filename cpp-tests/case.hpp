// A small reader of the exchange format (SPEC §7) for the C++ tests: Matrix Market
// coordinate files to 0-based CSR, vectors one number a line, and the few meta.json keys
// the tests need.
#ifndef FRICONT_CPP_TESTS_CASE_HPP
#define FRICONT_CPP_TESTS_CASE_HPP

#include <cstdint>
#include <fstream>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace casefile {

struct Csr {
    int64_t nrows = 0, ncols = 0;
    bool symmetric = false;  // a "symmetric" file: only its lower triangle is stored
    std::vector<int64_t> row_ptr, col_idx;
    std::vector<double> values;

    // y = M x (x: ncols values); for a symmetric file the full matrix is applied.
    std::vector<double> apply(const std::vector<double> &x) const {
        std::vector<double> y(static_cast<std::size_t>(nrows), 0.0);
        for (int64_t i = 0; i < nrows; i++)
            for (int64_t k = row_ptr[i]; k < row_ptr[i + 1]; k++) {
                y[i] += values[k] * x[col_idx[k]];
                if (symmetric && col_idx[k] != i) y[col_idx[k]] += values[k] * x[i];
            }
        return y;
    }
    // y = Mᵀ x (x: nrows values).
    std::vector<double> apply_t(const std::vector<double> &x) const {
        std::vector<double> y(static_cast<std::size_t>(ncols), 0.0);
        for (int64_t i = 0; i < nrows; i++)
            for (int64_t k = row_ptr[i]; k < row_ptr[i + 1]; k++) y[col_idx[k]] += values[k] * x[i];
        return y;
    }
};

inline std::ifstream open(const std::string &path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    return in;
}

inline Csr read_mtx(const std::string &path) {
    std::ifstream in = open(path);
    std::string line;
    std::getline(in, line);
    if (line.rfind("%%MatrixMarket", 0) != 0)
        throw std::runtime_error(path + ": not Matrix Market");
    Csr m;
    m.symmetric = line.find("symmetric") != std::string::npos;
    while (std::getline(in, line) && line[0] == '%') {
    }
    int64_t nnz = 0;
    std::istringstream(line) >> m.nrows >> m.ncols >> nnz;
    std::vector<int64_t> ri(nnz), ci(nnz);
    std::vector<double> v(nnz);
    m.row_ptr.assign(m.nrows + 1, 0);
    for (int64_t k = 0; k < nnz; k++) {
        if (!(in >> ri[k] >> ci[k] >> v[k])) throw std::runtime_error(path + ": short");
        ri[k]--;
        ci[k]--;
        m.row_ptr[ri[k] + 1]++;
    }
    std::partial_sum(m.row_ptr.begin(), m.row_ptr.end(), m.row_ptr.begin());
    std::vector<int64_t> next(m.row_ptr.begin(), m.row_ptr.end() - 1);
    m.col_idx.resize(nnz);
    m.values.resize(nnz);
    for (int64_t k = 0; k < nnz; k++) {
        int64_t pos = next[ri[k]]++;
        m.col_idx[pos] = ci[k];
        m.values[pos] = v[k];
    }
    return m;
}

inline std::vector<double> read_vec(const std::string &path, int64_t len) {
    std::ifstream in = open(path);
    std::vector<double> x(static_cast<std::size_t>(len));
    for (auto &xi : x)
        if (!(in >> xi)) throw std::runtime_error(path + ": too few numbers");
    return x;
}

inline std::string read_text(const std::string &path) {
    std::ifstream in = open(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// The text after "key": in a JSON object (enough for our meta.json files).
inline std::string json_at(const std::string &text, const std::string &key) {
    auto at = text.find("\"" + key + "\"");
    if (at == std::string::npos) throw std::runtime_error("meta.json lacks " + key);
    at = text.find(':', at);
    return text.substr(at + 1);
}

inline double json_number(const std::string &text, const std::string &key) {
    return std::stod(json_at(text, key));
}

struct Case {
    Csr a, n, t;
    std::vector<double> f0, f1, gap, friction;  // friction: p values
    double alpha_start = 0, alpha_end = 0;
};

inline Case read_case(const std::string &dir) {
    Case c;
    c.a = read_mtx(dir + "/A.mtx");
    c.n = read_mtx(dir + "/N.mtx");
    c.t = read_mtx(dir + "/T.mtx");
    const int64_t n = c.a.nrows, p = c.n.nrows;
    c.f0 = read_vec(dir + "/f0.txt", n);
    c.f1 = read_vec(dir + "/f1.txt", n);
    if (std::ifstream(dir + "/gap.txt")) c.gap = read_vec(dir + "/gap.txt", p);
    else c.gap.assign(p, 0.0);
    std::string meta = read_text(dir + "/meta.json");
    c.alpha_start = json_number(meta, "alpha_start");
    c.alpha_end = json_number(meta, "alpha_end");
    std::string fv = json_at(meta, "F");
    fv = fv.substr(fv.find_first_not_of(" \t\r\n"));
    if (fv[0] == '[') {
        std::string body = fv.substr(1, fv.find(']') - 1);
        for (char &ch : body)
            if (ch == ',') ch = ' ';
        std::istringstream in(body);
        double x;
        while (in >> x) c.friction.push_back(x);
    } else {
        c.friction.assign(p, std::stod(fv));
    }
    return c;
}

}  // namespace casefile

#endif
