// examples/type_list.hpp: a minimal type-list toolkit (the part of Boost.Mp11 the examples use).
//
// `product` builds the Cartesian product of policy lists, `filter` keeps the valid combinations,
// `filtered_product` does both without building the product, and `with_index` turns a run-time
// index into a compile-time type once, at the edge (STYLE rule 2): everything the callback does
// afterwards is monomorphic.
#pragma once

#include <array>
#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>

namespace nsp_examples::tl {

/// A list of types.
template <class... Ts>
struct list {};

/// The number of types in list L.
template <class L>
struct size_impl;
template <class... Ts>
struct size_impl<list<Ts...>> : std::integral_constant<std::size_t, sizeof...(Ts)> {};
template <class L>
inline constexpr std::size_t size = size_impl<L>::value;

/// The I-th type of list L.
template <class L, std::size_t I>
struct at_impl;
template <class... Ts, std::size_t I>
struct at_impl<list<Ts...>, I> {
    using type = std::tuple_element_t<I, std::tuple<Ts...>>;
};
template <class L, std::size_t I>
using at = typename at_impl<L, I>::type;

/// The concatenation of lists Ls. A fold over `+` rather than a recursion over Ls: a product of
/// the policy lists has about a thousand points, and filter concatenates one list per point,
/// which a pairwise recursion would nest beyond the compiler's template depth.
template <class... As, class... Bs>
list<As..., Bs...> operator+(list<As...>, list<Bs...>);  // declared only: used in decltype
template <class... Ls>
using concat = decltype((list<>{} + ... + Ls{}));

/// list<T, Us...> for every list<Us...> in the list of lists Ls.
template <class T, class Ls>
struct prepend_each_impl;
template <class T, class... Ls>
struct prepend_each_impl<T, list<Ls...>> {
    template <class L>
    struct one;
    template <class... Us>
    struct one<list<Us...>> {
        using type = list<T, Us...>;
    };
    using type = list<typename one<Ls>::type...>;
};

/// The Cartesian product of lists Ls: a list of list<T1, T2, ...>, first list varying slowest.
template <class... Ls>
struct product_impl {
    using type = list<list<>>;
};
template <class... Ts, class... Rest>
struct product_impl<list<Ts...>, Rest...> {
    using tail = typename product_impl<Rest...>::type;
    using type = concat<typename prepend_each_impl<Ts, tail>::type...>;
};
template <class... Ls>
using product = typename product_impl<Ls...>::type;

/// F<T> for every T of list L.
template <template <class> class F, class L>
struct transform_impl;
template <template <class> class F, class... Ts>
struct transform_impl<F, list<Ts...>> {
    using type = list<F<Ts>...>;
};
template <template <class> class F, class L>
using transform = typename transform_impl<F, L>::type;

/// The types T of list L for which Pred<T>::value is true, in order.
template <template <class> class Pred, class L>
struct filter_impl;
template <template <class> class Pred, class... Ts>
struct filter_impl<Pred, list<Ts...>> {
    using type = concat<std::conditional_t<Pred<Ts>::value, list<Ts>, list<>>...>;
};
template <template <class> class Pred, class L>
using filter = typename filter_impl<Pred, L>::type;

/// The points of product<Ls...> for which Pred<point>::value is true, in product order, without
/// building the product: point i is list<at<L1, i1>, at<L2, i2>, ...> with (i1, i2, ...) the
/// digits of i (first list slowest), each point is tested once and only the valid ones are
/// listed. filter<Pred, product<Ls...>> gives the same list, but GCC 12 spends time and memory
/// superlinear in the product's size on the concatenations that build it (the examples' product of
/// 2880 points per spectral mode took 92 s and 7 GB; this takes seconds).
template <template <class> class Pred, class... Ls>
struct filtered_product_impl {
    static constexpr std::array<std::size_t, sizeof...(Ls)> sizes{size<Ls>...};
    static constexpr std::size_t count = (std::size_t(1) * ... * size<Ls>);
    /// Digit k of point index i.
    static constexpr std::size_t digit(std::size_t i, std::size_t k) {
        for (std::size_t j = sizeof...(Ls); j-- > k + 1;) i /= sizes[j];
        return i % sizes[k];
    }
    template <std::size_t I, std::size_t... K>
    static auto point_of(std::index_sequence<K...>) -> list<at<Ls, digit(I, K)>...>;
    template <std::size_t I>
    using point = decltype(point_of<I>(std::index_sequence_for<Ls...>{}));

    template <std::size_t... I>
    static constexpr auto valid_of(std::index_sequence<I...>) {
        return std::array<bool, sizeof...(I)>{Pred<point<I>>::value...};
    }
    static constexpr std::array<bool, count> valid = valid_of(std::make_index_sequence<count>{});
    static constexpr std::size_t kept = [] {
        std::size_t n = 0;
        for (const bool v : valid) n += v ? 1 : 0;
        return n;
    }();
    static constexpr std::array<std::size_t, kept> indices = [] {
        std::array<std::size_t, kept> a{};
        std::size_t n = 0;
        for (std::size_t i = 0; i < count; ++i)
            if (valid[i]) a[n++] = i;
        return a;
    }();
    template <std::size_t... K>
    static auto pick(std::index_sequence<K...>) -> list<point<indices[K]>...>;
    using type = decltype(pick(std::make_index_sequence<kept>{}));
};
template <template <class> class Pred, class... Ls>
using filtered_product = typename filtered_product_impl<Pred, Ls...>::type;

/// Calls f(std::type_identity<T>{}) for every T of list L, in order.
template <class L, class F>
void for_each(F&& f) {
    [&]<class... Ts>(list<Ts...>) { (f(std::type_identity<Ts>{}), ...); }(L{});
}

/// Calls f(std::type_identity<at<L, i>>{}) for the run-time index i; returns false (and calls
/// nothing) when i is out of range. This is the one place a run-time choice becomes a type.
template <class L, class F>
bool with_index(std::size_t i, F&& f) {
    return [&]<std::size_t... Is>(std::index_sequence<Is...>) {
        return ((i == Is && (f(std::type_identity<at<L, Is>>{}), true)) || ...);
    }(std::make_index_sequence<size<L>>{});
}

static_assert(size<product<list<int, char>, list<float, double, long>>> == 6);
static_assert(std::is_same_v<at<product<list<int, char>, list<float, double>>, 1>, list<int, double>>);
static_assert(std::is_same_v<filter<std::is_integral, list<int, float, char>>, list<int, char>>);
template <class T>
struct second_is_integral : std::is_integral<at<T, 1>> {};
static_assert(std::is_same_v<filtered_product<second_is_integral, list<int, char>, list<float, long, double, short>>,
                             filter<second_is_integral, product<list<int, char>, list<float, long, double, short>>>>);

}  // namespace nsp_examples::tl
