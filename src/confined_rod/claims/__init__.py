"""TODO claims"""
