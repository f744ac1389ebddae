// The few Unreal types the plugin's C API layer touches (UhApi.h, UhTypes.h, UhSessionBuilder,
// UhConvert.h), as minimal stand-ins so that layer compiles and runs here against the real libuh.
// Not Unreal: TCHAR is char (UTF-8) and FString a std::string. Only what the layer uses is here;
// a plugin change that needs more fails this test's build, which is the point: look at what the
// plugin now calls and add its stand-in.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

using int32 = std::int32_t;
using int64 = std::int64_t;
using uint8 = std::uint8_t;
using uint32 = std::uint32_t;
using uint64 = std::uint64_t;
using TCHAR = char;
#define TEXT(x) x
#define UTF8_TO_TCHAR(x) (x)
#define INDEX_NONE (-1)
#define UNREALHAPTICSHAPTICO_API

class FString
{
public:
	FString() = default;
	FString(const TCHAR* Text) : Text_(Text != nullptr ? Text : "") {}
	const TCHAR* operator*() const { return Text_.c_str(); }
	bool IsEmpty() const { return Text_.empty(); }
	bool EndsWith(const TCHAR* Suffix) const
	{
		const std::string S(Suffix);
		return Text_.size() >= S.size() && Text_.compare(Text_.size() - S.size(), S.size(), S) == 0;
	}
	bool Contains(const TCHAR* Part) const { return Text_.find(Part) != std::string::npos; }
	bool StartsWith(const TCHAR* Prefix) const { return Text_.rfind(Prefix, 0) == 0; }
	friend FString operator+(const FString& A, const FString& B) { return FString((A.Text_ + B.Text_).c_str()); }
	friend FString operator+(const FString& A, const TCHAR* B) { return A + FString(B); }
	friend FString operator+(const TCHAR* A, const FString& B) { return FString(A) + B; }
	friend bool operator==(const FString& A, const FString& B) { return A.Text_ == B.Text_; }

private:
	std::string Text_;
};

template <typename T>
class TArray
{
public:
	TArray() = default;
	TArray(std::initializer_list<T> Items) : Items_(Items) {}
	int32 Num() const { return static_cast<int32>(Items_.size()); }
	T* GetData() { return Items_.data(); }
	const T* GetData() const { return Items_.data(); }
	void Add(const T& Item) { Items_.push_back(Item); }
	void Add(T&& Item) { Items_.push_back(std::move(Item)); }
	bool Contains(const T& Item) const
	{
		for (const T& I : Items_)
		{
			if (I == Item)
			{
				return true;
			}
		}
		return false;
	}
	T& operator[](int32 Index) { return Items_[static_cast<size_t>(Index)]; }
	const T& operator[](int32 Index) const { return Items_[static_cast<size_t>(Index)]; }
	auto begin() const { return Items_.begin(); }
	auto end() const { return Items_.end(); }

private:
	std::vector<T> Items_;
};

// The UTF-8 of a TCHAR string, alive as long as the converter.
class FTCHARToUTF8
{
public:
	explicit FTCHARToUTF8(const TCHAR* Text) : Utf8_(Text) {}
	const char* Get() const { return Utf8_.c_str(); }

private:
	std::string Utf8_;
};

struct FVector
{
	double X = 0, Y = 0, Z = 0;
	FVector() = default;
	FVector(double InX, double InY, double InZ) : X(InX), Y(InY), Z(InZ) {}
	friend FVector operator/(const FVector& V, double S) { return FVector(V.X / S, V.Y / S, V.Z / S); }
};

struct FQuat
{
	double X = 0, Y = 0, Z = 0, W = 1;
	FQuat() = default;
	FQuat(double InX, double InY, double InZ, double InW) : X(InX), Y(InY), Z(InZ), W(InW) {}
};
