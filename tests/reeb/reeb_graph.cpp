#include <catch2/catch.hpp>

#include <string>

#include "support/test_meshes.hpp"
#include "terrain/reeb/reeb_graph.hpp"

using namespace terrain;
using reeb::LinkClass;

TEST_CASE("Link classes follow the paper's table of lower and upper link components", "[reeb]") {
    CHECK(reeb::classify_link(0, 1) == LinkClass::morse_minimum);
    CHECK(reeb::classify_link(0, 2) == LinkClass::degenerate_minimum);
    CHECK(reeb::classify_link(1, 0) == LinkClass::morse_maximum);
    CHECK(reeb::classify_link(3, 0) == LinkClass::degenerate_maximum);
    CHECK(reeb::classify_link(1, 1) == LinkClass::regular);
    CHECK(reeb::classify_link(2, 2) == LinkClass::morse_saddle);
    CHECK(reeb::classify_link(3, 3) == LinkClass::degenerate_saddle);
    CHECK(reeb::classify_link(1, 2) == LinkClass::asymmetric_saddle);
    CHECK(std::string(reeb::to_string(LinkClass::morse_saddle)) == "morse_saddle");
    CHECK(std::string(reeb::to_string(reeb::NodeKind::maximum)) == "max");
}

TEST_CASE("A graph's arcs per node, counts and invariant check", "[reeb]") {
    const auto mesh = test::plate_mesh(10, 6, 1);
    const auto f = test::noise_field(mesh.vertex_count(), 5);
    const auto g = reeb::build_reeb_graph(mesh, f);
    REQUIRE(reeb::check_reeb_graph(g, f).empty());
    const auto s = reeb::summarize(g);
    CHECK(s.nodes == g.node_count());
    CHECK(s.critical == s.minima + s.maxima + s.saddles);
    CHECK(s.components == 1);
    CHECK(s.loops == 1);  // one hole
    const auto inc = reeb::node_arcs(g);
    std::size_t ends = 0;
    for (std::size_t n = 0; n < g.node_count(); ++n) {
        const auto degree = inc.degree(static_cast<std::int32_t>(n));
        CHECK((degree == 0) == !g.is_critical(static_cast<std::int32_t>(n)));
        ends += degree;
    }
    CHECK(ends == 2 * s.arcs);

    // Each broken invariant is named.
    REQUIRE(g.arc_count() > 0);
    auto turned = g;
    std::swap(turned.arcs[0][0], turned.arcs[0][1]);
    CHECK_FALSE(reeb::check_reeb_graph(turned, f).empty());
    auto moved = f;
    moved[0] += 1;
    CHECK(reeb::check_reeb_graph(g, moved).find("differs from its node's value") !=
          std::string::npos);
    auto kinds = g;
    for (auto& k : kinds.node_kinds)
        if (k == reeb::NodeKind::saddle) {  // arcs below: not a minimum
            k = reeb::NodeKind::minimum;
            break;
        }
    CHECK(reeb::check_reeb_graph(kinds, f).find("wrong arcs") != std::string::npos);
    auto lost = g;
    lost.vertex_nodes[0] = lost.vertex_nodes[0] == 0 ? 1 : 0;
    CHECK(reeb::check_reeb_graph(lost, f).find("wrong node") != std::string::npos);
}
