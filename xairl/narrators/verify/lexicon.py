"""Word lists the verifier reads names with: words that name nothing on their own, and abbreviations in feature
names with the words people write for them. One place, so that a newcomer adds a word here, not in a pattern."""

STOP = {"the", "a", "an", "of", "in", "on", "to", "for", "and", "or", "s", "its", "it", "by", "with", "at", "from",
        "per", "than", "is", "as", "out", "above", "below", "over", "under", "after", "before", "between", "within",
        "into", "onto", "about"}
#: words too generic to name a feature on their own
GENERIC = {"size", "area", "number", "total", "rate", "ratio", "level", "value", "values", "score", "type", "years",
           "year", "feature", "count", "amount", "length", "time", "state", "status", "quality", "id", "feet",
           "square", "sq", "ft", "kb", "m", "db", "dbm", "bit", "bits", "percent", "one", "two", "model", "data",
           "information", "prediction", "new", "old", "high", "low", "first", "second", "third", "average",
           "strongest", "weakest", "biggest", "largest", "main", "top", "overall",
           "other", "others"}  # rank words say which, not what
#: words of a span of time, generic too ('in the last two years' names no months_since_last_record), but never a
#: shared mention of the names that hold them
SPAN = {"last", "since", "today"}
GENERIC |= SPAN
#: units and statistics in names that never name a feature on their own ('14.7 min' is no mention of hm_pr_min, 'avg
#: 3.2' none of AvgWait5m), though a run of words holding them may
UNIT_PARTS = {"min", "max", "avg", "mean", "median", "pct", "num", "cnt", "yrs", "yr", "mins", "secs", "sec", "ms",
              "kg", "kmh", "mph", "usd", "eur"}
#: abbreviations in feature names and the words people write for them ('dist_to_charger_m': 'the distance')
ABBREVIATIONS = {"dist": "distance", "temp": "temperature", "avg": "average", "num": "number", "len": "length",
                 "qty": "quantity", "pct": "percent", "perc": "percent", "max": "maximum", "min": "minimum",
                 "cnt": "count", "amt": "amount", "freq": "frequency", "prev": "previous", "hr": "hour", "hrs": "hours",
                 "yrs": "years", "yr": "year", "mins": "minutes", "sec": "seconds", "secs": "seconds",
                 "wk": "week", "mo": "month", "mgmt": "management", "dept": "department", "emp": "employee",
                 "std": "deviation", "vol": "volume", "bal": "balance", "inc": "income", "pop": "population",
                 "elev": "elevation", "alt": "altitude", "lat": "latitude", "lon": "longitude", "lng": "longitude",
                 "spd": "speed", "accel": "acceleration", "humid": "humidity", "precip": "precipitation",
                 "batt": "battery", "conc": "concentration", "env": "environment", "cust": "customer",
                 # acronyms of their fields that people write out
                 "dti": "debt to income", "ltv": "loan to value", "soc": "state of charge", "bmi": "body mass index",
                 "anc": "neutrophil count", "crcl": "creatinine clearance", "inq": "inquiries",
                 "abx": "antibiotics", "int": "interest"}
#: words of feature names and other words people write for the same thing ('battery_pct': 'the charge'); each makes
#: one more spelling of the name, so a word shared by two names ('charge') names both, ambiguously
SYNONYMS = {"battery": ("charge",), "temperature": ("fever",), "heart": ("pulse",), "distance": ("far",),
            "hr": ("heart rate", "pulse"), "bp": ("blood pressure",), "qty": ("quantity",), "price": ("cost",),
            "cost": ("price",), "speed": ("velocity",), "velocity": ("speed",)}
#: participles that name a feature whose words are said the other way round ('year built' -> 'the build year')
BASE_FORM = {"built": "build", "sold": "sale", "made": "make", "paid": "pay", "owned": "own", "used": "use"}
IRREGULAR = {"keep": "kept", "go": "went", "choose": "chose", "hold": "held", "run": "ran", "stay": "stayed"}
#: closed classes of categorical values: a label holding one member makes any other member, said in a sentence that
#: names its feature, a wrong value ('Because it was June, the month term added ...' when the month is August; 'in
#: late lactation' when the stage is early)
CLOSED_CLASSES = (
    frozenset({"january", "february", "march", "april", "june", "july", "august", "september", "october", "november",
               "december"}),  # (not 'may': a verb)
    frozenset({"monday", "tuesday", "wednesday", "thursday", "friday", "saturday", "sunday"}),
    frozenset({"winter", "spring", "summer", "autumn"}),  # (not 'fall': a verb)
    frozenset({"north", "south", "east", "west", "northeast", "northwest", "southeast", "southwest"}),
    frozenset({"morning", "afternoon", "evening", "night", "overnight"}),
    # opposites: a label of one is the other said wrongly ('in late lactation' when the stage is early)
    frozenset({"early", "late"}), frozenset({"inside", "outside"}), frozenset({"open", "closed"}),
    frozenset({"fixed", "flexible"}), frozenset({"indoor", "outdoor"}), frozenset({"urban", "rural"}),
)
#: hedges before a ratio's number ('by roughly 1.5 to 1', 'by about 3 to 2'), as a regex group
RATIO_HEDGE = r"(?:about\s+|roughly\s+|around\s+|nearly\s+|almost\s+|some\s+|~\s*)?"
