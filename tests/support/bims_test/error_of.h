// The message of the error a call throws, for tests that check what an error
// says.
#pragma once

#include <exception>
#include <functional>
#include <string>

namespace bims::test
{
/** The what() of the E that \a f throws; \a none when it throws nothing
 * (another exception type passes through, failing the test). */
template <typename E = std::exception>
std::string errorOf(const std::function<void()>& f,
                    const std::string& none = {})
{
	try
	{
		f();
	}
	catch (const E& e)
	{
		return e.what();
	}
	return none;
}
}  // namespace bims::test
