#include "lonlat_mapping.hpp"

#include <cpl_conv.h>
#include <tbb/enumerable_thread_specific.h>

#include <cmath>
#include <vector>

#include "terrain/core/error.hpp"
#include "terrain/internal/geo/lonlat_frame.hpp"

namespace terrain::geo {
namespace {

class BaseLonLat final : public LonLatMapping {
  public:
    BaseLonLat(std::string crs, LonLatTransform first) : crs_(std::move(crs)) {
        const char* options[] = {"FORMAT=WKT2_2019", "MULTILINE=NO", nullptr};
        char* text = nullptr;
        first.geographic->exportToWkt(&text, options);
        wkt_ = text ? text : "";
        CPLFree(text);
        transforms_.local() = std::make_unique<LonLatTransform>(std::move(first));
    }

    bool to_lonlat(std::size_t count, double* x, double* y, std::uint8_t* ok) const override {
        if (count == 0) return true;
        const GdalErrorCapture quiet;
        auto& local = transforms_.local();
        if (!local) local = std::make_unique<LonLatTransform>(make_lonlat_transform(crs_));
        std::vector<int> done(count, 0);
        const bool any =
            local->to_lonlat && local->to_lonlat->Transform(count, x, y, nullptr, done.data());
        bool all = any;
        for (std::size_t i = 0; i < count; ++i) {
            const bool good = any && done[i] && std::isfinite(x[i]) && std::isfinite(y[i]);
            if (ok) ok[i] = good;
            all = all && good;
        }
        return all;
    }

    std::string lonlat_crs_wkt() const override { return wkt_; }

  private:
    std::string crs_, wkt_;
    mutable tbb::enumerable_thread_specific<std::unique_ptr<LonLatTransform>> transforms_;
};

class OutputLonLat final : public LonLatMapping {
  public:
    OutputLonLat(std::string crs, bool earth, std::array<double, 2> centre,
                 std::unique_ptr<LonLatFrame> first)
        : crs_(std::move(crs)), earth_(earth), centre_(centre), wkt_(first->wkt()) {
        frames_.local() = std::move(first);
    }

    bool to_lonlat(std::size_t count, double* x, double* y, std::uint8_t* ok) const override {
        const GdalErrorCapture quiet;
        auto& local = frames_.local();
        if (!local) local = std::make_unique<LonLatFrame>(crs_, earth_, centre_, "crs");
        return local->transform(count, x, y, ok);
    }

    std::string lonlat_crs_wkt() const override { return wkt_; }

  private:
    std::string crs_;
    bool earth_;
    std::array<double, 2> centre_;
    std::string wkt_;
    mutable tbb::enumerable_thread_specific<std::unique_ptr<LonLatFrame>> frames_;
};

}  // namespace

std::shared_ptr<const LonLatMapping> make_lonlat_mapping(const std::string& crs,
                                                         LonLatTransform first) {
    if (!first.to_lonlat) return nullptr;
    return std::make_shared<BaseLonLat>(crs, std::move(first));
}

std::shared_ptr<const LonLatMapping> make_output_lonlat_mapping(const std::string& crs, bool earth,
                                                                std::array<double, 2> centre) {
    std::unique_ptr<LonLatFrame> first;
    try {
        first = std::make_unique<LonLatFrame>(crs, earth, centre, "crs");
    } catch (const Error&) {
        return nullptr;
    }
    return std::make_shared<OutputLonLat>(crs, earth, centre, std::move(first));
}

}  // namespace terrain::geo
